"""``hexdem signals``: measured accelerometer signals aligned with a run's sensor particles."""

from __future__ import annotations


def add_arguments(parser) -> None:
    parser.add_argument(
        "--measured",
        required=True,
        metavar="FILE.csv",
        help="measured signals, columns sensor,time,ax,ay (SI; sensors named as in the run)",
    )
    parser.add_argument("--run", required=True, metavar="DIR", help="a hexdem run with sensors (its sensors.csv)")
    parser.add_argument("--out", metavar="DIR", help="output directory (default: the run's directory)")


def run(args) -> None:
    from hexdem.experiments.signals import compare_signals

    summary = compare_signals(args.run, args.measured, args.out)
    print(
        f"hexdem: aligned on sensor {summary['aligned_on']} (time offset {summary['time_offset_s'] * 1e6:.2f} µs); "
        f"{len(summary['sensors'])} sensors compared"
    )
