"""``hexdem design``: which beads to instrument, and at which striker speed, for the keys a
calibration is to tell (:mod:`hexdem.design.study`)."""

from __future__ import annotations

from hexdem.calibration.study import DEFAULT_GAIN_SD, DEFAULT_SPEED_SCATTER
from hexdem.cli.options import add_workers_or_parsl


def add_arguments(parser) -> None:
    parser.add_argument(
        "--config", metavar="BASE.toml", help="the base configuration (default: the paper's experiment)"
    )
    parser.add_argument(
        "--prior",
        action="append",
        default=[],
        required=True,
        metavar="KEY=DIST",
        help="a key to be told and its prior, as hexdem calibrate takes it (repeat for more keys)",
    )
    parser.add_argument("--sensors", type=int, required=True, metavar="N", help="sensor particles per design")
    parser.add_argument(
        "--candidates",
        default="all",
        metavar="all|lines|SENSOR,...",
        help="the beads a sensor may replace: every bead, the observation lines' beads, or a list such as "
        "0:1,0:3,+30:2 (default all; never the struck bead)",
    )
    parser.add_argument(
        "--speeds",
        metavar="V1,V2,...",
        help="striker speeds a design may choose among (default: the configuration's v0)",
    )
    parser.add_argument(
        "--records",
        type=int,
        default=20,
        metavar="R",
        help="impacts per design, each on a packing of its own (default 20)",
    )
    parser.add_argument(
        "--noise",
        type=float,
        required=True,
        metavar="M_S2",
        help="the accelerometers' noise, rms in m/s2 per channel at the configuration's sensor_rate_hz",
    )
    parser.add_argument(
        "--sensor-gain-sd",
        type=float,
        default=DEFAULT_GAIN_SD,
        metavar="S",
        help=f"each sensor's unknown gain ~ N(1, S), common to its records (default {DEFAULT_GAIN_SD})",
    )
    parser.add_argument(
        "--realizations",
        type=int,
        metavar="K",
        help="disordered packings per parameter set (default: 8 with a prior on diameter_sigma_m, else 1)",
    )
    parser.add_argument(
        "--out", required=True, metavar="DIR", help="design.csv, design.json, design.png and simulations/ (resumable)"
    )
    parser.add_argument(
        "--budget", type=int, metavar="N", help="simulations in all (default: 10 (keys + 1) x speeds x K)"
    )
    parser.add_argument("--seed", type=int, default=0, metavar="S", help="seed of the parameter sets and packings")
    add_workers_or_parsl(parser, 1, "simulations at once, locally (default 1)")


def run(args) -> None:
    from hexdem.design.study import prepare_design, run_design
    from hexdem.experiments.sweep_plan import read_base

    study = prepare_design(
        read_base(args.config),
        args.prior,
        args.sensors,
        args.candidates,
        args.speeds,
        args.records,
        args.noise,
        args.sensor_gain_sd,
        DEFAULT_SPEED_SCATTER,
        args.realizations,
        args.budget,
        args.seed,
    )
    summary = run_design(study, args.out, args.workers, args.parsl, log=lambda m: print(f"hexdem: {m}", flush=True))
    best = summary["best"]
    widths = ", ".join(f"{prior.key} {best[f'width_{prior.key}']:.3g}" for prior in study.priors)
    print(f"best: sensors {best['sensors']} at {best['v_striker']:g}; expected 90 % widths {widths}")
    for name, entry in (summary.get("paper_configurations") or {}).items():
        if entry is not None:
            paper = ", ".join(f"{key} {w:.3g}" for key, w in entry["widths"].items())
            print(f"paper configuration {name}: {' '.join(entry['sensors'])}: {paper}")
    print(f"hexdem: {summary['simulations']['runs']} simulations; results in {args.out}")
