"""Scaling-law tables and figures of Sec. V (Figs. 6 and 7) in one command.

    python workflows/scaling_laws.py --out results/scaling                    # reference, < 2 min
    python workflows/scaling_laws.py --out results/scaling-lammps --engine lammps \\
        --compare-with results/scaling                                         # ~5 min

Runs ``hexdem scaling`` (30 V₀ from 0.01 to 0.30, both strikes, all four combinations) and
records its wall time in ``OUT/workflow.json``. With ``--compare-with DIR`` it also compares
this run's ``scaling.json`` and ``decay_fits.csv`` with those in DIR (typically the other
engine) and writes ``OUT/engine_agreement.csv``: for every coefficient the relative
difference and the number of agreeing significant digits, −log10(|a − b| / |a|).
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
import time
from pathlib import Path

from hexdem.cli.main import main as hexdem
from hexdem.common.io import write_csv, write_json

COEFFICIENTS = ("m", "b", "alpha", "beta", "gamma")


def agreeing_digits(a: float, b: float) -> float:
    """−log10 of the relative difference (inf when equal)."""
    if a == b:
        return math.inf
    return -math.log10(abs(a - b) / max(abs(a), abs(b)))


def compare(out: Path, other: Path) -> list[tuple]:
    """Rows (quantity, combination, this, other, relative difference, digits) for the laws' coefficients
    and for every per-V₀ decay rate c."""
    ours, theirs = (json.loads((d / "scaling.json").read_text()) for d in (out, other))
    rows = []
    for name in ("30/30", "30/0", "0/0", "0/30"):
        for key in COEFFICIENTS:
            a, b = ours[name][key], theirs[name][key]
            if a is not None:
                rows.append((key, name, a, b, abs(a - b) / abs(b), agreeing_digits(a, b)))
    fits = [
        {(r["combination"], r["v0"]): float(r["c"]) for r in csv.DictReader(open(d / "decay_fits.csv"))}
        for d in (out, other)
    ]
    for (name, v0), a in fits[0].items():
        b = fits[1][(name, v0)]
        rows.append((f"c(V0={float(v0):.3f})", name, a, b, abs(a - b) / abs(b), agreeing_digits(a, b)))
    return rows


def run(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, metavar="DIR")
    parser.add_argument("--engine", choices=("reference", "lammps"), default="reference")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--compare-with", metavar="DIR", help="a finished scaling run to compare with")
    args = parser.parse_args(argv)
    out = Path(args.out)
    start = time.perf_counter()
    status = hexdem(["scaling", "--out", str(out), "--engine", args.engine, "--workers", str(args.workers)])
    if status:
        return status
    wall = time.perf_counter() - start
    record = {
        "command": "python workflows/scaling_laws.py " + " ".join(sys.argv[1:] if argv is None else argv),
        "engine": args.engine,
        "workers": args.workers,
        "wall_time_s": wall,
    }
    if args.compare_with:
        rows = compare(out, Path(args.compare_with))
        write_csv(
            out / "engine_agreement.csv",
            ("quantity", "combination", "this", "other", "relative_difference", "digits"),
            rows,
        )
        laws = [r for r in rows if r[0] in COEFFICIENTS]
        record["compared_with"] = str(args.compare_with)
        record["min_digits_laws"] = min(r[5] for r in laws)
        record["min_digits_c"] = min(r[5] for r in rows if r[0].startswith("c("))
        print(
            f"agreement with {args.compare_with}: laws >= {record['min_digits_laws']:.2f} digits, "
            f"per-V0 c >= {record['min_digits_c']:.2f} digits",
            file=sys.stderr,
        )
    write_json(out / "workflow.json", record)
    print(f"scaling_laws: {wall:.1f} s wall time, results in {out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(run())
