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
from pathlib import Path

from record import WorkflowRecord


def run(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, metavar="DIR")
    parser.add_argument("--ranks", type=int, default=2, help="MPI ranks for the half-hexagon (default 2)")
    args = parser.parse_args(argv)
    out = Path(args.out)
    commands = {
        "fig3": ["snapshots", "--shape", "hexagon", "--out", str(out / "fig3")],
        "fig4": ["snapshots", "--shape", "half-hexagon", "--ranks", str(args.ranks), "--out", str(out / "fig4")],
    }
    record = WorkflowRecord(__file__, argv)
    for name, command in commands.items():
        status = record.run(name, command)
        if status:
            return status
        summary = json.loads((out / name / "snapshots.json").read_text())
        record.steps[name].update(ranks=summary["ranks"], atom_steps_per_s=summary["atom_steps_per_s"])
    record.finish(out)
    return 0


if __name__ == "__main__":
    sys.exit(run())
