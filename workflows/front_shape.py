"""Does the uncompressed lattice's front become round, and how fast? One command.

    python workflows/front_shape.py --out results/front-shape [--ranks 2] [--radius-beads 170] [--edge-beads 110]
                                    [--launcher CMD]

Strikes a half-disc of ``--radius-beads`` d about the struck bead (default 170: 52,599 beads) as
in the experiment (steel, 0.4 m/s, 0°, the struck edge's delrin wall) and, as a control, a hexagon
of ``--edge-beads`` per edge precompressed at 20 N per contact and struck weakly (1e-4 m/s);
follows the relative sixfold amplitude of the half-maximum arrival front against its mean radius
from 5 to beyond 150 bead diameters, over one sixfold period of rays about the strike direction,
each read until the front is 10 d from the packing's edge; and fits A(R) = A∞ + B (R/d)^−p
(:mod:`hexdem.experiments.front_study`). Writes
``OUT/front_shape.csv`` (``packing,time,mean_radius_d,sixfold_amplitude,bins_used,sixfold_cos,sixfold_sin``),
``OUT/front_shape_fit.json``, ``OUT/front_shape.png``, both runs' ``hexdem run`` files in
``OUT/uncompressed`` and ``OUT/precompressed``, and ``OUT/workflow.json``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from hexdem.cli.main import exit_status
from hexdem.cli.options import add_launcher
from hexdem.common.io import write_json
from hexdem.errors import HexdemError
from hexdem.experiments.front_study import FrontStudy, run_front_study


def run(argv=None) -> int:
    defaults = FrontStudy()
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, metavar="DIR")
    parser.add_argument("--ranks", type=int, default=defaults.ranks, help="MPI ranks per run (default 2)")
    parser.add_argument(
        "--radius-beads",
        type=int,
        default=defaults.radius_beads,
        help=f"radius of the half-disc in bead diameters (default {defaults.radius_beads})",
    )
    parser.add_argument(
        "--edge-beads",
        type=int,
        default=defaults.edge_beads,
        help=f"beads per edge of the control's hexagon (default {defaults.edge_beads})",
    )
    parser.add_argument("--fronts", type=int, default=defaults.fronts, help=f"front times (default {defaults.fronts})")
    add_launcher(parser)
    args = parser.parse_args(argv)
    study = FrontStudy(
        edge_beads=args.edge_beads,
        radius_beads=args.radius_beads,
        ranks=args.ranks,
        launcher=args.launcher,
        fronts=args.fronts,
    )
    start = time.perf_counter()
    try:
        summary = run_front_study(
            study, args.out, log=lambda message: print(f"front_shape: {message}", file=sys.stderr)
        )
    except HexdemError as exc:
        print(f"front_shape: error: {exc}", file=sys.stderr)
        return exit_status(exc)
    wall = time.perf_counter() - start
    write_json(
        Path(args.out) / "workflow.json",
        {
            "command": "python workflows/front_shape.py " + " ".join(sys.argv[1:] if argv is None else argv),
            "wall_time_s": wall,
        },
    )
    for name, fit in summary["fits"].items():
        print(
            f"{name}: A = {fit['a_inf']:.4f} ± {fit['a_inf_se']:.4f} + {fit['b']:.3f} (R/d)^-{fit['p']:.2f} over "
            f"R = {fit['radius_min_d']:.1f}..{fit['radius_max_d']:.1f} d ({wall:.0f} s in all)"
        )
    return 0


if __name__ == "__main__":
    sys.exit(run())
