"""What the benchmarks share: the bare yardstick deck, config files for the CLI, and a subprocess
runner that records wall time and each process's peak resident memory.

**Peak RSS per process.** :func:`run_watched` starts the command and, until it exits, reads
``VmHWM`` (the kernel's high-water mark of resident memory) from ``/proc/<pid>/status`` of it
and of all its descendants (found through the parent pid in ``/proc/<pid>/stat``) every
``SAMPLE_S``; ``VmHWM`` only grows, so the last reading of a process is its peak up to then.
Under ``mpiexec`` this sees every rank (and the launcher and its proxies) separately, which a
single ``/usr/bin/time -v`` cannot tell apart. What happens after a process's last reading is
caught by the ``ru_maxrss`` that ``wait4`` returns for the command (what ``/usr/bin/time -v``
prints as "Maximum resident set size"): the largest peak of any single process of the tree,
since each parent reaps its children and the kernel keeps the maximum. The reported peak per
process is the larger of the two.
"""

from __future__ import annotations

import os
import subprocess
import tempfile
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from hexdem.engines.lammps.deck import Deck, write_deck
from hexdem.engines.lammps.driver import split_deck
from hexdem.model.config import RunConfig
from hexdem.model.granular import GranularModel, RunSettings

#: The deck's set-up commands and its ``run``, without the output section (no dump, no Python).
NOOUTPUT_NAME = "in.nooutput"
#: Seconds between looks at a watched process tree (one look reads /proc: a few ms).
SAMPLE_S = 0.2
MB = 1e6


def nooutput_deck(model: GranularModel, settings: RunSettings, directory) -> Deck:
    """Render the deck of ``model`` into ``directory`` and add ``in.nooutput``: everything
    before its output section, then ``run n_steps`` (what a bare LAMMPS run of hexdem's work is)."""
    deck = write_deck(model, settings, directory)
    setup, _ = split_deck(deck.input_path.read_text())
    (deck.directory / NOOUTPUT_NAME).write_text(f"{setup}run             {settings.n_steps}\n")
    return deck


def _toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(item) for item in value) + "]"
    return repr(value)


def write_config(config: RunConfig, path) -> Path:
    """``config`` as a TOML file that ``hexdem run --config`` reads back to the same config: the keys
    that differ from the defaults (so that an earlier hexdem, without today's newer keys, reads it)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    defaults = RunConfig().as_dict()
    lines = [
        f"{key} = {_toml_value(value)}"
        for key, value in config.as_dict().items()
        if value is not None and value != defaults[key]
    ]
    path.write_text("\n".join(lines) + "\n")
    assert RunConfig.from_toml(path) == config
    return path


def _children() -> dict[int, list[int]]:
    children: dict[int, list[int]] = {}
    for entry in os.scandir("/proc"):
        if not entry.name.isdigit():
            continue
        try:
            with open(f"/proc/{entry.name}/stat") as fh:
                ppid = int(fh.read().rsplit(")", 1)[1].split()[1])
        except (OSError, IndexError, ValueError):
            continue
        children.setdefault(ppid, []).append(int(entry.name))
    return children


def _descendants(root: int) -> list[int]:
    children, found, todo = _children(), [], [root]
    while todo:
        pid = todo.pop()
        found.append(pid)
        todo.extend(children.get(pid, ()))
    return found


def _status(pid: int) -> tuple[str, int] | None:
    """(name, VmHWM [bytes]) of a live process, or None."""
    try:
        with open(f"/proc/{pid}/status") as fh:
            fields = dict(line.split(":", 1) for line in fh if ":" in line)
    except OSError:
        return None
    if "VmHWM" not in fields:  # a zombie
        return None
    return fields["Name"].strip(), int(fields["VmHWM"].split()[0]) * 1024


@dataclass
class Watched:
    """A finished command: ``wall_s``, ``returncode``, ``stderr``, ``peaks`` {pid: (name, VmHWM
    bytes)} as last sampled, ``tree_maxrss`` the largest single-process peak from ``wait4``, ``pid``
    the command's own process (its descendants are the others in ``peaks``)."""

    wall_s: float
    returncode: int
    stderr: str
    peaks: dict[int, tuple[str, int]] = field(default_factory=dict)
    tree_maxrss: int = 0
    pid: int = 0

    @property
    def peak_per_process(self) -> int:
        """The largest peak resident memory of any one process of the command [bytes]."""
        return max([self.tree_maxrss, *(rss for _, rss in self.peaks.values())])

    def check(self, what: str) -> Watched:
        if self.returncode != 0:
            raise SystemExit(f"{what} failed (exit status {self.returncode}):\n{self.stderr[-3000:]}")
        return self


def run_watched(command, cwd=None, env=None) -> Watched:
    """Run ``command`` (stdout discarded), sampling its process tree's peak memory (see module
    docstring); returns its :class:`Watched` record. A thread blocks in ``wait4``, so that the
    wall time ends when the command does, not at the next sample."""
    peaks: dict[int, tuple[str, int]] = {}
    ended: dict = {}
    finished = threading.Event()
    with open(os.devnull, "w") as devnull, tempfile.TemporaryFile() as err:
        start = time.perf_counter()
        process = subprocess.Popen(command, cwd=cwd, env=env, stdout=devnull, stderr=err)

        def reap():
            _, status, usage = os.wait4(process.pid, 0)
            ended.update(time=time.perf_counter(), status=status, usage=usage)
            finished.set()

        waiter = threading.Thread(target=reap, daemon=True)
        waiter.start()
        while not finished.is_set():
            for child in _descendants(process.pid):
                if (state := _status(child)) is not None:
                    peaks[child] = state
            finished.wait(SAMPLE_S)
        waiter.join()
        process.returncode = os.waitstatus_to_exitcode(ended["status"])
        err.seek(0)
        stderr = err.read().decode(errors="replace")
    return Watched(
        ended["time"] - start, process.returncode, stderr, peaks, ended["usage"].ru_maxrss * 1024, process.pid
    )
