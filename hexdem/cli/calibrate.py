"""``hexdem calibrate``: the model's parameters from measured sensor records, with uncertainties
(:mod:`hexdem.calibration.study`)."""

from __future__ import annotations

from hexdem.calibration.observables import ACCELERATION_UNITS
from hexdem.calibration.study import DEFAULT_GAIN_SD, DEFAULT_SPEED_SCATTER
from hexdem.cli.options import add_workers_or_parsl


def add_arguments(parser) -> None:
    parser.add_argument(
        "--config",
        metavar="BASE.toml",
        help="the base configuration, with the measured sensors in its sensors (default: the paper's "
        "11-per-edge steel experiment, which lists none)",
    )
    parser.add_argument(
        "--measured",
        required=True,
        metavar="DATA.csv",
        help="measured accelerometer records: columns sensor,time,ax,ay (ay absent for single-axis "
        "sensors; times in s, accelerations in --acceleration-unit) and optionally record (one "
        "record per impact), at one steady sampling rate, with a quiet lead-in before the pulse",
    )
    parser.add_argument(
        "--prior",
        action="append",
        default=[],
        required=True,
        metavar="KEY=DIST",
        help="a calibrated key and its prior: uniform(a, b), loguniform(a, b) or normal(mu, sigma); "
        "KEY is a numeric run-config key, a path such as materials.NAME.youngs_modulus_pa, or "
        "diameter_sigma_m, the standard deviation of the bead diameters in m (the disorder of "
        "hexdem ensemble; the paper's is 6 tol = 7.62e-5), which simulates every parameter set on "
        "disordered packings (repeat for more keys)",
    )
    parser.add_argument(
        "--out",
        required=True,
        metavar="DIR",
        help="posterior.csv, calibration.json, posterior.png, predictive.png and simulations/ (one "
        "folder per simulation); rerunning the same command resumes it",
    )
    parser.add_argument(
        "--realizations",
        type=int,
        metavar="K",
        help="disordered packings per parameter set, prepared as hexdem ensemble prepares them (default: "
        "8 with a prior on diameter_sigma_m, else 1, the ideal lattice; with K > 1 and no such "
        "prior, sigma is the paper's)",
    )
    parser.add_argument(
        "--budget",
        type=int,
        metavar="N",
        help="simulations in all, parameter sets times K (default: (30 per parameter + 30) x K; at "
        "least (15 per parameter + 15) x K)",
    )
    parser.add_argument(
        "--sensor-gain-sd",
        type=float,
        default=DEFAULT_GAIN_SD,
        metavar="S",
        help="each sensor's sensitivity is an unknown gain ~ N(1, S), the same in all its records, "
        f"marginalised and reported (default {DEFAULT_GAIN_SD}: a calibrated accelerometer's "
        "sensitivity is known to about 2 %%; 0 for records made by hexdem)",
    )
    parser.add_argument(
        "--speed-scatter",
        type=float,
        default=DEFAULT_SPEED_SCATTER,
        metavar="S",
        help="the striker's speed varies from record to record with this relative standard deviation "
        f"around the calibrated one (default {DEFAULT_SPEED_SCATTER}: a striker released the same "
        "way each time; 0 for records made by hexdem)",
    )
    parser.add_argument(
        "--acceleration-unit",
        choices=sorted(ACCELERATION_UNITS),
        default="m/s2",
        help="the unit of the measured file's ax and ay (default m/s2; g: multiples of standard gravity, 9.80665 m/s2)",
    )
    parser.add_argument(
        "--no-model-discrepancy",
        dest="model_discrepancy",
        action="store_false",
        help="take the model as exact: no discrepancy term (by default a relative model error tau, "
        "log-uniform on [1e-4, 0.2], common to all records, is sampled with the parameters)",
    )
    parser.add_argument(
        "--seed",
        type=int,
        default=0,
        metavar="S",
        help="seed of every random choice: the same seed gives the same posterior (default 0)",
    )
    add_workers_or_parsl(parser, 1, "simulations at once, locally (default 1)")


def run(args) -> None:
    from hexdem.calibration.study import calibrate, prepare
    from hexdem.experiments.sweep_plan import read_base

    calibration = prepare(
        read_base(args.config),
        args.measured,
        args.prior,
        args.budget,
        args.seed,
        args.realizations,
        args.sensor_gain_sd,
        args.speed_scatter,
        args.acceleration_unit,
        args.model_discrepancy,
    )
    summary = calibrate(
        calibration,
        args.measured,
        args.out,
        args.workers,
        args.parsl,
        log=lambda message: print(f"hexdem: {message}", flush=True),
    )
    for key, entry in summary["parameters"].items():
        print(
            f"{key}: median {entry['median']:.6g}, 90 % interval [{entry['q05']:.6g}, {entry['q95']:.6g}] "
            f"({entry['width_ratio']:.0%} of the prior's)"
        )
    print(f"hexdem: {summary['simulations']['runs']} simulations; results in {args.out}")
