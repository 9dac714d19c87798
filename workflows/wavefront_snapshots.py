"""Wavefront snapshots of Figs. 3 and 4 and the tables behind them in one command.

    python workflows/wavefront_snapshots.py --out results/wavefront [--ranks 2]   # about 20 s

Runs ``hexdem snapshots`` on the 11-per-edge hexagon (Fig. 3, one rank) into ``OUT/fig3``
and on the half-hexagon with a long edge of 91 beads and short edges of 46 (Fig. 4, with
the walls of the small hexagon outlined) on ``--ranks`` MPI ranks through ``mpiexec`` into
``OUT/fig4``, both struck by a striker at 0.40 m/s, and records the commands, wall times and
LAMMPS speeds in ``OUT/workflow.json``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from hexdem.cli.main import main as hexdem
from hexdem.common.io import write_json


def run(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, metavar="DIR")
    parser.add_argument("--ranks", type=int, default=2, help="MPI ranks for the half-hexagon (default 2)")
    args = parser.parse_args(argv)
    out = Path(args.out)
    commands = {"fig3": ["snapshots", "--shape", "hexagon", "--out", str(out / "fig3")],
                "fig4": ["snapshots", "--shape", "half-hexagon", "--ranks", str(args.ranks),
                         "--out", str(out / "fig4")]}
    record = {"command": "python workflows/wavefront_snapshots.py " + " ".join(sys.argv[1:] if argv is None else argv)}
    for name, command in commands.items():
        start = time.perf_counter()
        status = hexdem(command)
        if status:
            return status
        summary = json.loads((out / name / "snapshots.json").read_text())
        record[name] = {"hexdem_command": "hexdem " + " ".join(command), "wall_time_s": time.perf_counter() - start,
                        "ranks": summary["ranks"], "atom_steps_per_s": summary["atom_steps_per_s"]}
    write_json(out / "workflow.json", record)
    print(f"wavefront_snapshots: {sum(r['wall_time_s'] for r in record.values() if isinstance(r, dict)):.1f} s "
          f"wall time, results in {out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(run())
