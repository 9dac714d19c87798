"""TCA figures of Sec. IV (Fig. 5) in one command.

    python workflows/tca_figures.py --out results/tca [--engine lammps]

Runs ``hexdem tca --out DIR`` (ω, c, Fig. 5a pulse speeds at V₀ = 0.1 nondimensional with a
30° strike, Fig. 5b arrival times of the 11-per-edge experiment at 0.4 m/s with a 0° strike)
and records its wall time in ``OUT/workflow.json``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from hexdem.cli.main import main as hexdem
from hexdem.common.io import write_json


def run(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, metavar="DIR")
    parser.add_argument("--engine", choices=("reference", "lammps"), default="reference")
    args = parser.parse_args(argv)
    start = time.perf_counter()
    status = hexdem(["tca", "--out", args.out, "--engine", args.engine])
    if status:
        return status
    wall = time.perf_counter() - start
    write_json(
        Path(args.out) / "workflow.json",
        {
            "command": "python workflows/tca_figures.py " + " ".join(sys.argv[1:] if argv is None else argv),
            "engine": args.engine,
            "wall_time_s": wall,
        },
    )
    print(f"tca_figures: {wall:.1f} s wall time, results in {args.out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(run())
