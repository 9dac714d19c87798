"""``hexdem paper``: the whole paper in one command (see :mod:`hexdem.paper.pipeline`).

Writes ``DIR/report.html`` (self-contained), ``DIR/report.md`` and
``DIR/published_vs_computed.csv`` (columns item, quantity, combination, published, computed,
difference, protocol), with every part's files in its own folder. A rerun resumes.
"""

from __future__ import annotations

from hexdem.cli.options import add_launcher, add_parsl
from hexdem.common.machine import usable_cpus
from hexdem.model.config import STEPS_PER_CONTACT


def add_arguments(parser) -> None:
    parser.add_argument("--out", metavar="DIR", required=True, help="output directory (rerun to resume)")
    parser.add_argument(
        "--workers",
        type=int,
        default=min(2, usable_cpus()),
        metavar="N",
        help="processes at once: the studies' runs, the MPI ranks of Fig. 4 (default 2)",
    )
    parser.add_argument(
        "--quick",
        action="store_true",
        help="fewer V0, realizations, disorders and frictions, smaller packings, same code paths (rough numbers)",
    )
    add_parsl(parser)
    add_launcher(parser, "-n N and each run's job")
    parser.add_argument(
        "--steps-per-contact",
        type=int,
        default=STEPS_PER_CONTACT,
        metavar="N",
        help=f"time step of the LAMMPS impacts: the Hertz contact time / N (default {STEPS_PER_CONTACT}; "
        "a multiple of 14 of at least 28: the impacts are sampled every 1/14 of it; 700 was the former default)",
    )


def run(args) -> None:
    from hexdem.paper.pipeline import run_paper
    from hexdem.paper.settings import PaperSettings

    run_paper(
        PaperSettings(
            quick=args.quick,
            workers=args.workers,
            launcher=args.launcher,
            parsl=args.parsl,
            steps_per_contact=args.steps_per_contact,
        ),
        args.out,
    )
