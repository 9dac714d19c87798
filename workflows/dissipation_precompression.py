"""What dissipation and precompression do to the wave, in one command (issue: Sec. VI-B, Sec. VII).

    python workflows/dissipation_precompression.py --out results/dissipation-precompression   # about a minute

The experiment's hexagon (11 steel beads per edge, delrin walls, V0 = 0.4 m/s on the centre bead
of an edge, 0° strike) is run with ``hexdem run`` for each coefficient of restitution e in
{1, 0.95, 0.9, 0.8} (uncompressed) and each static contact force f0 in {0, 1, 5, 20} N (no
dissipation), each into its own directory with its arrival map and decay plot. Then:

* ``dissipation_precompression.csv``: per run and observation line, the decay rate c of the peak
  speeds, V_n = V_s c^{n − s} (s = 2 on the 0° line, 1 on the ±30° lines, beads up to 8,
  log-linear fit, :func:`hexdem.theory.scaling.fit_decay`) with its standard error, and the
  front speed along the 0° line (slope of x_n against the half-maximum arrival time, beads 2 to 8);
* ``decay_and_speed.png``: c and the front speed against e and against f0;
* ``workflow.json``: the commands and their wall times.
"""

from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

import numpy as np
from record import WorkflowRecord

from hexdem.analysis.plotting import save, subplots
from hexdem.common.io import write_csv
from hexdem.theory.scaling import fit_decay

RESTITUTIONS = (1.0, 0.95, 0.9, 0.8)
PRECOMPRESSIONS_N = (0.0, 1.0, 5.0, 20.0)
START = {"0": 2, "+30": 1, "-30": 1}
LAST = 8
COLUMNS = ("restitution", "precompression_n", "line", "decay_rate", "decay_rate_stderr", "front_speed_m_s")


def measure(run_dir: Path, restitution: float, f0: float) -> list[tuple]:
    """Rows of the table for one run, from its ``peaks.csv``."""
    with open(run_dir / "peaks.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    zero = [r for r in rows if r["line"] == "0" and 2 <= int(r["n"]) <= LAST]
    speed = np.polyfit([float(r["arrival_time"]) for r in zero], [float(r["x"]) for r in zero], 1)[0]
    table = []
    for line, start in START.items():
        beads = [r for r in rows if r["line"] == line]
        n = np.array([int(r["n"]) for r in beads])
        c, c_err = fit_decay(n, np.array([float(r["peak_speed"]) for r in beads]), start, LAST)
        table.append((restitution, f0, line, c, c_err, float(speed)))
    return table


def figure(rows: list[tuple], path: Path) -> None:
    fig, axes = subplots(2, 2, figsize=(10, 7), layout="constrained")
    for column, (key, _values, label) in enumerate(
        (
            (0, RESTITUTIONS, "coefficient of restitution e  (f0 = 0)"),
            (1, PRECOMPRESSIONS_N, "static contact force f0 [N]  (e = 1)"),
        )
    ):
        other = 1 - key
        chosen = [r for r in rows if r[other] == (0.0 if key == 0 else 1.0)]
        for line, marker in zip(START, "o^v"):
            points = sorted((r[key], r[3], r[4]) for r in chosen if r[2] == line)
            x, c, err = (np.array(v) for v in zip(*points))
            axes[0, column].errorbar(x, c, yerr=err, marker=marker, label=f"{line}°", capsize=3)
        front = sorted({(r[key], r[5]) for r in chosen})
        axes[1, column].plot(*zip(*front), marker="o", color="k")
        axes[0, column].set_ylabel("decay rate c  ($V_n = V_s c^{n-s}$)")
        axes[1, column].set_ylabel("front speed along 0° [m/s]")
        axes[1, column].set_xlabel(label)
        axes[0, column].legend(title="line")
        for ax in axes[:, column]:
            ax.grid(True, alpha=0.3)
    fig.suptitle("Dissipation and precompression, 11-per-edge hexagon, V0 = 0.4 m/s")
    save(fig, path)


def run(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, metavar="DIR")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    cases = sorted({(e, 0.0) for e in RESTITUTIONS} | {(1.0, f0) for f0 in PRECOMPRESSIONS_N}, reverse=True)
    record = WorkflowRecord(__file__, argv)
    rows = []
    for e, f0 in cases:
        name = f"e{e:.2f}_f{f0:g}N"
        (out / f"{name}.toml").write_text(f"restitution = {e!r}\nprecompression_n = {f0!r}\n")
        command = ["run", "--config", str(out / f"{name}.toml"), "--out", str(out / name)]
        status = record.run(name, command)
        if status:
            return status
        rows += measure(out / name, e, f0)
    write_csv(out / "dissipation_precompression.csv", COLUMNS, rows)
    figure(rows, out / "decay_and_speed.png")
    record.finish(out)
    return 0


if __name__ == "__main__":
    sys.exit(run())
