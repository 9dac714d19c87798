"""``hexdem compare``: one configuration through LAMMPS and the reference integrator."""

from __future__ import annotations

from hexdem.cli.options import add_launcher
from hexdem.cli.run import config_from_args
from hexdem.errors import HexdemError


def add_arguments(parser) -> None:
    parser.add_argument(
        "--config",
        metavar="FILE.toml",
        help="parameters (keys: RunConfig fields; 'engine' is "
        "ignored); default: the paper's 11-per-edge steel experiment",
    )
    parser.add_argument(
        "--out",
        metavar="DIR",
        default="compare",
        help="output directory (default: compare/): compare.csv, compare.json, compare.png, "
        "and each engine's run in lammps/ and reference/",
    )
    parser.add_argument("--ranks", type=int, metavar="N", help="MPI ranks for LAMMPS (default 1, in-process)")
    add_launcher(parser)
    parser.add_argument(
        "--peak-tol",
        type=float,
        metavar="REL",
        help="allowed relative peak-speed difference (default: 4 times LAMMPS's expected error at "
        "the run's steps per contact, 1.6e-4 at the default 140 without damping)",
    )
    parser.add_argument(
        "--arrival-tol",
        type=float,
        metavar="SECONDS",
        help="allowed arrival-time difference in seconds at the impact (default: likewise, 9.2e-5 "
        "contact times at 140 steps per contact, 0.0066 µs on the paper's experiment)",
    )
    parser.add_argument(
        "--arrival-rate",
        type=float,
        metavar="FRACTION",
        help="its growth per second of the bead's arrival time (default: likewise, 5.3e-5 at 140 "
        "steps per contact; 0 when --arrival-tol is given)",
    )
    parser.set_defaults(engine="lammps", dump=None, movie=None)  # (the file's engine is checked as LAMMPS's)


def run(args) -> None:
    from hexdem.experiments.compare import Tolerances, run_comparison

    overrides = {
        key: value
        for key, value in (
            ("peak_rel", args.peak_tol),
            ("arrival_s", args.arrival_tol),
            ("arrival_rate", args.arrival_rate),
        )
        if value is not None
    }
    tolerances = Tolerances(**overrides)
    comparison = run_comparison(config_from_args(args), args.out, tolerances=tolerances)
    if not comparison.agree:
        raise HexdemError(f"{comparison.verdict()}; see {args.out}/compare.csv")
    print(f"hexdem: {comparison.verdict()}")
