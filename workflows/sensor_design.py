"""Where the paper's sensors should have gone: ``hexdem design`` for the experiment of Sec. II.

    python workflows/sensor_design.py --out results/sensor-design [--records 20] [--noise 5]
        [--workers 2 | --parsl CONFIG.py] [--quick]

The paper's experiment (the 11-per-edge steel hexagon, a striker), with the disorder's σ and the
restitution unknown (priors σ ~ uniform(0, 2e-4) m and restitution ~ uniform(0.8, 0.99), as the
calibration workflow's), 4 sensors, ``--records`` packings struck (the paper's 20), at one of the
speeds 0.25, 0.40 or 0.70 m/s, accelerometer noise ``--noise`` m/s² rms, records of 3 ms (the
calibration workflow's :data:`RECORD_DURATION_S`: at σ = 6 tol the pulse can reach a sensor
2.3 ms after the impact). Which sensors and which speed tell both keys best, and how much narrower
would the intervals be than with the paper's configurations 1–3? Writes ``OUT/design/`` (the
command's ``design.csv``, ``design.json``, ``design.png``), ``OUT/sensor_design.csv``
(``design,sensors,v_striker,criterion,width_diameter_sigma_m,width_restitution``: the best design
and configurations 1–3 at its speed) and ``OUT/workflow.json``. ``--quick``: the lines' beads only,
2 packings a parameter set, 10 parameter sets a speed (60 simulations): the same path in a
twelfth of the simulations.
"""

from __future__ import annotations

import argparse
import sys
import time

from hexdem.cli.main import exit_status
from hexdem.common.io import ensure_writable_dir, write_csv, write_json
from hexdem.design.study import prepare_design, run_design
from hexdem.errors import HexdemError

PRIORS = ("diameter_sigma_m=uniform(0, 2e-4)", "restitution=uniform(0.8, 0.99)")
SPEEDS = "0.25,0.40,0.70"
RECORD_DURATION_S = 3e-3
COLUMNS = ("design", "sensors", "v_striker", "criterion", "width_diameter_sigma_m", "width_restitution")


def run(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, metavar="DIR")
    parser.add_argument("--records", type=int, default=20, help="packings struck per design (default 20)")
    parser.add_argument("--noise", type=float, default=5.0, help="accelerometer noise [m/s² rms] (default 5)")
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--parsl", metavar="CONFIG.py")
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args(argv)
    start = time.perf_counter()
    try:
        out = ensure_writable_dir(args.out)
        study = prepare_design(
            {"duration": RECORD_DURATION_S},
            PRIORS,
            4,
            "lines" if args.quick else "all",
            SPEEDS,
            args.records,
            args.noise,
            0.02,
            0.01,
            2 if args.quick else None,
            60 if args.quick else None,
            0,
        )
        summary = run_design(
            study,
            out / "design",
            args.workers,
            args.parsl,
            log=lambda message: print(f"sensor_design: {message}", file=sys.stderr, flush=True),
        )
        best = summary["best"]
        rows = [("best", best["sensors"], best["v_striker"], best["criterion"], *_widths(best))]
        for name, entry in summary["paper_configurations"].items():
            if entry is not None:
                widths = [entry["widths"][key] for key in ("diameter_sigma_m", "restitution")]
                rows.append(
                    (
                        f"configuration {name}",
                        " ".join(entry["sensors"]),
                        entry["v_striker"],
                        entry["criterion"],
                        *widths,
                    )
                )
        write_csv(out / "sensor_design.csv", COLUMNS, rows)
    except HexdemError as exc:
        print(f"sensor_design: error: {exc}", file=sys.stderr)
        return exit_status(exc)
    write_json(
        out / "workflow.json",
        {
            "command": "python workflows/sensor_design.py " + " ".join(sys.argv[1:] if argv is None else argv),
            "simulations": summary["simulations"]["runs"],
            "wall_time_s": time.perf_counter() - start,
        },
    )
    for row in rows:
        print(
            f"{row[0]}: {row[1]} at {row[2]:g} m/s: σ's 90 % width {row[4] * 1e6:.3g} µm, "
            f"the restitution's {row[5]:.3g}"
        )
    return 0


def _widths(row: dict) -> list[float]:
    return [row["width_diameter_sigma_m"], row["width_restitution"]]


if __name__ == "__main__":
    sys.exit(run())
