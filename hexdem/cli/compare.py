"""``hexdem compare``: one configuration through LAMMPS and the reference integrator."""

from __future__ import annotations

from hexdem.cli.options import add_launcher
from hexdem.cli.run import config_from_args
from hexdem.errors import HexdemError


def add_arguments(parser) -> None:
    parser.add_argument("--config", metavar="FILE.toml", help="parameters (keys: RunConfig fields; 'engine' is "
                        "ignored); default: the paper's 11-per-edge steel experiment")
    parser.add_argument("--out", metavar="DIR", default="compare",
                        help="output directory (default: compare/): compare.csv, compare.json, compare.png, "
                        "and each engine's run in lammps/ and reference/")
    parser.add_argument("--ranks", type=int, metavar="N", help="MPI ranks for LAMMPS (default 1, in-process)")
    add_launcher(parser)
    parser.add_argument("--peak-tol", type=float, metavar="REL",
                        help="allowed relative peak-speed difference (default: 4 times LAMMPS's expected error at "
                        "the run's steps per contact, 1.6e-4 at the default 140 without damping)")
    parser.add_argument("--arrival-tol", type=float, metavar="SECONDS",
                        help="allowed arrival-time difference in seconds (default: likewise, 8.2e-4 contact "
                        "times at 140 steps per contact, 0.059 µs on the paper's experiment)")
    parser.set_defaults(engine=None, dump=None, movie=None)


def run(args) -> None:
    from hexdem.experiments.compare import Tolerances, run_comparison

    overrides = {key: value for key, value in (("peak_rel", args.peak_tol), ("arrival_s", args.arrival_tol))
                 if value is not None}
    tolerances = Tolerances(**overrides)
    comparison = run_comparison(config_from_args(args), args.out, tolerances=tolerances)
    if not comparison.agree:
        raise HexdemError(f"{comparison.verdict()}; see {args.out}/compare.csv")
    print(f"hexdem: {comparison.verdict()}")
