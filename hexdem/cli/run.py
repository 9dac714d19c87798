"""``hexdem run``: one impact simulation, written to an output directory."""

from __future__ import annotations

from hexdem.cli.options import add_launcher
from hexdem.model.config import ENGINES, RunConfig
from hexdem.model.unused_keys import check_unused_keys


def add_arguments(parser) -> None:
    parser.add_argument(
        "--config",
        metavar="FILE.toml",
        help="parameters (keys: RunConfig fields); default: the paper's 11-per-edge steel experiment",
    )
    parser.add_argument("--out", metavar="DIR", default="results", help="output directory (default: results/)")
    parser.add_argument("--ranks", type=int, metavar="N", help="MPI ranks for LAMMPS (default 1, in-process)")
    parser.add_argument("--engine", choices=ENGINES, help="integrator (default: lammps)")
    add_launcher(parser)
    parser.add_argument(
        "--dump",
        action="store_true",
        default=None,
        help="also write LAMMPS's full trajectory dump into DIR/deck (config key dump = true)",
    )
    parser.add_argument(
        "--movie",
        action="store_true",
        default=None,
        help="also write DIR/movie.gif, the speed field animated from samples taken in the run "
        "(config key movie = true)",
    )


def config_from_args(args) -> RunConfig:
    """The config file (or the defaults) with command-line overrides applied, refused if it sets a
    key that its other keys leave without effect (:func:`~hexdem.model.unused_keys.check_unused_keys`)."""
    config = RunConfig.from_toml(args.config) if args.config else RunConfig()
    overrides = {
        key: value
        for key, value in (
            ("ranks", args.ranks),
            ("engine", args.engine),
            ("dump", args.dump),
            ("movie", args.movie),
            ("launcher", args.launcher),
        )
        if value is not None
    }
    config = config.override(**overrides)
    check_unused_keys(config)
    return config


def run(args) -> None:
    from hexdem.experiments.run import run_experiment

    run_experiment(config_from_args(args), args.out)
