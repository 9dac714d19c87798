"""The precompressed lattice's Dirac point, conical diffraction and the transition to the
linear regime: the paper's second open question, in one command.

    python workflows/dirac_point.py --out results/dirac-point [--quick] [--ranks 2] [--engine lammps]

Measures the phonon bands of a hexagon of 40 per edge precompressed at 20 N per contact under
random velocities, a Gaussian packet (σ = 12 d) at the Dirac point K opening into a ring and a
control packet away from K, and the front's shape and speed over precompression against impact
speed (:mod:`hexdem.waves.study`). ``--quick`` (the test suite's) uses 20 per edge, σ = 8 d and a
small sweep. Writes into OUT: ``dispersion.csv`` (``path_position,kx,ky,branch,omega_theory,omega_measured,
relative_deviation,bound,resolved,within_bound``: each point against its own bound),
``conical.csv`` (``time_s,ring_radius_d,theory_radius_d``), ``control.csv``, ``transition.csv``,
``dirac_point.json``, ``bands.png``, ``conical.png``, ``snapshots.png``, ``conical.gif``,
``transition_map.png``, ``dirac_point.html``, the runs under ``runs/`` and ``workflow.json``.
"""

from __future__ import annotations

import argparse
import sys
import time

from hexdem.cli.main import exit_status
from hexdem.common.io import ensure_writable_dir, write_json
from hexdem.errors import HexdemError
from hexdem.waves.study import DiracStudy, run_dirac_study


def run(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, metavar="DIR")
    parser.add_argument("--quick", action="store_true", help="the test suite's smaller case")
    parser.add_argument("--ranks", type=int, default=2, help="MPI ranks per LAMMPS run (default 2)")
    parser.add_argument(
        "--engine",
        choices=("lammps", "reference"),
        default="lammps",
        help="the engine of every run (default lammps; the reference runs on one rank)",
    )
    args = parser.parse_args(argv)

    def log(message):
        print(f"dirac_point: {message}", file=sys.stderr, flush=True)

    start = time.perf_counter()
    try:
        study = (DiracStudy.quick() if args.quick else DiracStudy()).on(
            args.engine, args.ranks if args.engine == "lammps" else 1
        )
        out = ensure_writable_dir(args.out)
        result = run_dirac_study(study, out, log)
    except HexdemError as exc:
        print(f"dirac_point: error: {exc}", file=sys.stderr)
        return exit_status(exc)
    wall = time.perf_counter() - start
    write_json(
        out / "workflow.json",
        {
            "command": "python workflows/dirac_point.py " + " ".join(sys.argv[1:] if argv is None else argv),
            "wall_time_s": wall,
        },
    )
    theory = result["theory"]
    spread = result["dispersion"]
    log(
        f"ω_K/2π = {theory['dirac_frequency_hz']:.1f} Hz, v_D = {theory['cone_slope_m_s']:.2f} m/s; dispersion "
        f"{100 * spread['median_relative_deviation']:.2f} % (median), worst beyond the resolution limit "
        f"{100 * spread['largest_resolved_relative_deviation']:.1f} % (its bound "
        f"{100 * spread['largest_resolved_bound']:.1f} %), {spread['resolved_points_within_bound']} of "
        f"{spread['resolved_points']} resolved points within their bounds; ring growth "
        f"{100 * result['conical']['slope_relative_deviation']:.2f} % from v_D; {wall:.0f} s in all"
    )
    log(result["transition"]["finding"])
    return 0


if __name__ == "__main__":
    sys.exit(run())
