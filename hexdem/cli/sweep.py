"""``hexdem sweep``: a study of any run-config keys (:mod:`hexdem.experiments.sweep`)."""

from __future__ import annotations

from hexdem.cli.options import add_launcher


def add_arguments(parser) -> None:
    parser.add_argument("--config", metavar="BASE.toml", help="the base configuration (keys: RunConfig fields); "
                        "default: the paper's 11-per-edge steel experiment")
    parser.add_argument("--vary", action="append", default=[], metavar="KEY=V1,V2,...", required=True,
                        help="a key and its values (repeat for more keys: the runs are the product); KEY may be "
                             "nested, e.g. regions.0.material or impacts.1.v0")
    parser.add_argument("--out", metavar="DIR", required=True,
                        help="the sweep's directory: runs/ (one result directory per run), sweep.csv, sweep.png; "
                             "rerunning the same command resumes it")
    parser.add_argument("--workers", type=int, default=1, metavar="N", help="runs at once (default 1)")
    add_launcher(parser)


def run(args) -> None:
    from hexdem.experiments.sweep import run_sweep
    from hexdem.experiments.sweep_plan import Variation, read_base

    variations = [Variation.parse(option) for option in args.vary]
    run_sweep(read_base(args.config), variations, args.out, args.workers, args.launcher,
              source=args.config or "the default configuration")
