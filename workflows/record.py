"""What every multi-step workflow shares: run ``hexdem`` commands, time them, record them.

``OUT/workflow.json`` holds ``command`` (the workflow's own command line) and, per step, the
``hexdem_command`` it ran and its ``wall_time_s``.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

from hexdem.cli.main import main as hexdem
from hexdem.common.io import write_json


class WorkflowRecord:
    """The steps of workflow ``script`` started with ``argv`` (None: this process's arguments)."""

    def __init__(self, script: str, argv=None):
        self.name = Path(script).stem
        arguments = sys.argv[1:] if argv is None else argv
        self.steps: dict = {"command": f"python workflows/{Path(script).name} " + " ".join(arguments)}

    def run(self, step: str, command: list[str]) -> int:
        """``hexdem COMMAND`` as step ``step``; its exit status (0: success)."""
        start = time.perf_counter()
        status = hexdem(command)
        self.steps[step] = {"hexdem_command": "hexdem " + " ".join(command), "wall_time_s": time.perf_counter() - start}
        return status

    def finish(self, out: Path) -> None:
        """Write ``OUT/workflow.json`` and say how long it all took."""
        write_json(out / "workflow.json", self.steps)
        total = sum(step["wall_time_s"] for step in self.steps.values() if isinstance(step, dict))
        print(f"{self.name}: {total:.1f} s wall time, results in {out}", file=sys.stderr)
