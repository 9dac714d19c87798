"""``hexdem calibrate``: the model's parameters from measured sensor records, with uncertainties
(:mod:`hexdem.calibration.study`)."""

from __future__ import annotations

from hexdem.cli.options import add_parsl


def add_arguments(parser) -> None:
    parser.add_argument("--config", metavar="BASE.toml",
                        help="the base configuration, with the measured sensors in its sensors (default: the paper's "
                             "11-per-edge steel experiment, which lists none)")
    parser.add_argument("--measured", required=True, metavar="DATA.csv",
                        help="measured accelerometer records: columns sensor,time,ax,ay (SI) and optionally record "
                             "(one record per impact)")
    parser.add_argument("--prior", action="append", default=[], required=True, metavar="KEY=DIST",
                        help="a calibrated key and its prior: uniform(a, b), loguniform(a, b) or normal(mu, sigma); "
                             "KEY is a numeric run-config key or a path such as materials.NAME.youngs_modulus_pa "
                             "(repeat for more keys)")
    parser.add_argument("--out", required=True, metavar="DIR",
                        help="posterior.csv, calibration.json, posterior.png, predictive.png and simulations/ (one "
                             "folder per simulation); rerunning the same command resumes it")
    parser.add_argument("--realizations", type=int, default=1, metavar="K", help="packings per parameter set (default 1)")
    parser.add_argument("--budget", type=int, metavar="N",
                        help="simulations in all (default: 30 per parameter + 30; at least 15 per parameter + 15)")
    parser.add_argument("--seed", type=int, default=0, metavar="S",
                        help="seed of every random choice: the same seed gives the same posterior (default 0)")
    parser.add_argument("--workers", type=int, default=1, metavar="N", help="simulations at once, locally (default 1)")
    add_parsl(parser)


def run(args) -> None:
    from hexdem.calibration.study import calibrate, prepare
    from hexdem.experiments.sweep_plan import read_base

    calibration = prepare(read_base(args.config), args.measured, args.prior, args.budget, args.seed, args.realizations)
    summary = calibrate(calibration, args.measured, args.out, args.workers, args.parsl,
                        log=lambda message: print(f"hexdem: {message}", flush=True))
    for key, entry in summary["parameters"].items():
        print(f"{key}: median {entry['median']:.6g}, 90 % interval [{entry['q05']:.6g}, {entry['q95']:.6g}] "
              f"({entry['width_ratio']:.0%} of the prior's)")
    print(f"hexdem: {summary['simulations']['runs']} simulations; results in {args.out}")
