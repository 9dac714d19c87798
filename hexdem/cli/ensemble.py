"""``hexdem ensemble``: weakly disordered packings struck by a striker (Sec. VI; Figs. 8, 9).

Runs (or resumes) the ensemble in ``--out``, every deck of its preparation and every impact one
task of ``--workers`` local processes or of Parsl (``--parsl CONFIG.py``), and
writes ``peaks_stats.csv``, ``ideal_peaks.csv``, ``arrival_map.csv``, ``disorder_effect.csv``,
``ensemble.json`` and the PNGs of Figs. 8 and 9 (see :mod:`hexdem.disorder.ensemble`,
:mod:`hexdem.disorder.stats`).
"""

from __future__ import annotations

import re

from hexdem.cli.options import add_launcher, add_workers_or_parsl
from hexdem.common.machine import usable_cpus
from hexdem.errors import HexdemError

DEFAULT_VELOCITIES = "0.25,0.40,0.70"
_NUMBER = r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?"


def parse_numbers(
    text: str, option: str = "--velocities", unit: str = "m/s", example: str = DEFAULT_VELOCITIES
) -> tuple[float, ...]:
    """ "0.25,0.40,0.70" → (0.25, 0.4, 0.7); anything else is a HexdemError naming ``option``."""
    items = [item.strip() for item in str(text).split(",")]
    if not all(re.fullmatch(_NUMBER, item) for item in items):
        raise HexdemError(f"{option} must be comma-separated numbers in {unit}, e.g. {example}; got {text!r}")
    return tuple(float(item) for item in items)


def parse_bead(text: str) -> tuple[int, int]:
    """ "0,2" → (0, 2): a bead's paper labels {m, n}."""
    match = re.fullmatch(r"\s*([+-]?\d+)\s*,\s*([+-]?\d+)\s*", str(text))
    if not match:
        raise HexdemError(f"--reference-bead must be the labels M,N of a bead, e.g. 0,2; got {text!r}")
    return int(match.group(1)), int(match.group(2))


def add_arguments(parser) -> None:
    parser.add_argument(
        "--out",
        metavar="DIR",
        required=True,
        help="ensemble directory (rerun with the same options to resume an interrupted ensemble)",
    )
    parser.add_argument("--realizations", type=int, default=20, metavar="R", help="disordered packings (default 20)")
    parser.add_argument(
        "--velocities",
        default=DEFAULT_VELOCITIES,
        metavar="V1,V2,...",
        help=f"striker speeds in m/s (default {DEFAULT_VELOCITIES})",
    )
    parser.add_argument("--seed", type=int, default=0, help="seed of the diameters (default 0)")
    add_workers_or_parsl(
        parser,
        usable_cpus(),
        "decks (local processes) at once (default: the CPUs this job "
        "may use, its CPU affinity as Slurm or taskset set it)",
    )
    add_launcher(parser, "-n 1 and each deck's lmp or impact's job")
    parser.add_argument(
        "--shape", default="hexagon", help="packing: hexagon, square or centered-square (default hexagon)"
    )
    parser.add_argument("--edge-beads", type=int, default=11, help="beads per hexagon edge (default 11)")
    parser.add_argument("--rows", type=int, default=15, help="rows of a square or centered-square crystal (default 15)")
    parser.add_argument(
        "--columns", type=int, default=15, help="columns of a square or centered-square crystal (default 15)"
    )
    parser.add_argument("--tol-mm", type=float, help="diameter tolerance tol in mm (default 0.0127)")
    parser.add_argument("--sigma-mm", type=float, help="standard deviation of the diameters in mm (default 6 tol)")
    parser.add_argument(
        "--tilt-deg",
        type=float,
        default=5.0,
        help="tilt of the set-up: gravity g sin(tilt) along the strike (default 5)",
    )
    parser.add_argument(
        "--push-force",
        type=float,
        metavar="NEWTON",
        help="inward force on the edge beads while compacting (default 5 on the hexagon, "
        "0.05 on the crystals, whose rows buckle at 5)",
    )
    parser.add_argument(
        "--max-settle-steps",
        type=int,
        default=1_000_000,
        metavar="N",
        help="steps after which a preparation stage that has not settled is an error (default 1e6)",
    )
    parser.add_argument(
        "--duration-ms",
        type=float,
        help="length of every impact run in ms (default: 1.5 x the ideal lattice's crossing estimate)",
    )
    parser.add_argument(
        "--reference-bead",
        default="0,2",
        metavar="M,N",
        help="bead whose arrival is t = 0 in the arrival maps (default 0,2: bead 1 of the 0° line)",
    )
    parser.add_argument("--scaling", metavar="scaling.json", help="draw the fitted laws of hexdem scaling in Fig. 9")
    parser.add_argument("--keep-dumps", action="store_true", help="keep the impact dumps (about 20 MB each)")


def config_from_args(args):
    from hexdem.disorder.ensemble import EnsembleConfig
    from hexdem.disorder.preparation import CRYSTAL_PUSH_FORCE_N, Disorder, Preparation
    from hexdem.model.materials import PAPER_DIAMETER_M

    sizes = {
        name: value * 1e-3 for name, value in (("tol_m", args.tol_mm), ("sigma_m", args.sigma_mm)) if value is not None
    }
    disorder = Disorder(PAPER_DIAMETER_M, **sizes)
    push = args.push_force
    if push is None:
        push = Preparation.push_force_n if args.shape == "hexagon" else CRYSTAL_PUSH_FORCE_N
    preparation = Preparation(push_force_n=push, tilt_deg=args.tilt_deg, max_steps=args.max_settle_steps)
    return EnsembleConfig(
        realizations=args.realizations,
        velocities_m_s=parse_numbers(args.velocities),
        seed=args.seed,
        shape=args.shape,
        edge_beads=args.edge_beads,
        rows=args.rows,
        columns=args.columns,
        disorder=disorder,
        preparation=preparation,
        duration_s=None if args.duration_ms is None else args.duration_ms * 1e-3,
        reference_bead=parse_bead(args.reference_bead),
    )


def run(args) -> None:
    from hexdem.disorder.runner import run_ensemble

    run_ensemble(
        config_from_args(args),
        args.out,
        workers=args.workers,
        launcher=args.launcher,
        parsl=args.parsl,
        keep_dumps=args.keep_dumps,
        scaling_json=args.scaling,
    )
