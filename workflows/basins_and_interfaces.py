"""Basins, interfaces, several strikers and a ring front, in the spirit of Hua & Van Gorder, in one command.

    python workflows/basins_and_interfaces.py --out results/basins [--quick]    # about 1 min on 2 cores

Runs ``hexdem run --movie`` on each case of :data:`CASES` (its config is written to
``OUT/configs/NAME.toml``; the run's files, the movie included, go to ``OUT/NAME``):

* the three basins struck at the centre of an edge: hexagon, triangle, disc (curved wall);
* a steel | brass and a steel | PTFE interface through the middle of the experiment's hexagon,
  struck from the steel side for 3 ms: the share of the energy on each side against time, which
  reads as transmission across the interface or trapping on the struck side (Tichler et al.,
  PRL 2013; Hua & Van Gorder);
* a symmetric double strike (the centres of two opposite edges) and a flat striker on a whole edge;
* an interior impact in a precompressed hexagon, the ring-shaped front of Chong et al.
  (arXiv 1510.03674).

Writes ``OUT/interfaces.csv`` (``case,time_ms,struck_side_fraction,far_side_fraction``),
``OUT/interfaces.png``, ``OUT/trapping.json`` (each interface's far-side share at the end and
its largest), ``OUT/workflow.json`` (commands, sizes, wall times) and ``OUT/index.html``, a page
with every case's config, maps, energy figure and movie. ``--quick``: smaller packings and
shorter runs (for the tests).
"""

from __future__ import annotations

import argparse
import csv
import html
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

from hexdem.analysis.plotting import SINGLE_PLOT_MARGINS, save, set_title, subplots
from hexdem.cli.main import exit_status
from hexdem.common.io import atomic_path, write_csv, write_json
from hexdem.errors import HexdemError
from hexdem.experiments.run import run_experiment
from hexdem.model.config import RunConfig

#: Each case: (what it shows, its config as a user would write it).
CASES = {
    "hexagon": (
        "The experiment's hexagonal basin, struck at the centre of an edge",
        """
edge_beads = 11
""",
    ),
    "triangle": (
        "A triangular basin struck at the centre of an edge: the front meets the two far walls at once",
        """
shape = "triangle"
edge_beads = 19
""",
    ),
    "disc": (
        "A circular basin (a curved wall) struck at its leftmost bead",
        """
shape = "disc"
radius_beads = 10
""",
    ),
    "steel_brass": (
        "A steel | brass interface through the middle of the hexagon, struck from the steel side",
        """
duration = 3e-3
[[regions]]
material = "brass"
x_min_d = 8.0
""",
    ),
    "steel_ptfe": (
        "A steel | PTFE interface through the middle of the hexagon, struck from the steel side",
        """
duration = 3e-3
[[regions]]
material = "ptfe"
x_min_d = 8.0
""",
    ),
    "double_strike": (
        "Two equal strikes at the centres of opposite edges: the fronts meet in the middle",
        """
[[impacts]]
site = [0, 0]
[[impacts]]
site = [0, 20]
angle_deg = 180.0
""",
    ),
    "flat_striker": (
        "A flat striker on the whole left edge (a row of 11 touching steel spheres): a plane-like front",
        """
impact = "striker"
[[impacts]]
edge_deg = 0.0
""",
    ),
    "ring": (
        "An interior impact in a hexagon precompressed at 20 N per contact: the ring-shaped front",
        """
edge_beads = 15
precompression_n = 20.0
[[impacts]]
site = [0, 14]
v0 = 0.01
""",
    ),
}
#: --quick: smaller packings and shorter runs, the same kinds of cases.
QUICK = {
    "hexagon": {"edge_beads": 5},
    "triangle": {"edge_beads": 8},
    "disc": {"radius_beads": 4},
    "steel_brass": {"edge_beads": 5, "duration": 6e-4, "regions": ({"material": "brass", "x_min_d": 3.0},)},
    "steel_ptfe": {"edge_beads": 5, "duration": 6e-4, "regions": ({"material": "ptfe", "x_min_d": 3.0},)},
    "double_strike": {"edge_beads": 5, "impacts": ({"site": [0, 0]}, {"site": [0, 8], "angle_deg": 180.0})},
    "flat_striker": {"edge_beads": 5},
    "ring": {"edge_beads": 5, "impacts": ({"site": [0, 4], "v0": 0.01},)},
}
INTERFACES = ("steel_brass", "steel_ptfe")
INTERFACE_COLUMNS = ("case", "time_ms", "struck_side_fraction", "far_side_fraction")
FIGURES = ("arrival_map.png", "peak_map.png", "energy_regions.png", "movie.gif")


def side_fractions(directory: Path) -> list[tuple[float, float, float]]:
    """(time [ms], struck side's share, far side's share) of an interface run's energy_regions.csv."""
    shares: dict[float, dict[str, float]] = {}
    with open(directory / "energy_regions.csv", newline="") as fh:
        for row in csv.DictReader(fh):
            shares.setdefault(float(row["time"]), {})[row["region"]] = float(row["energy_fraction"])
    return [(t * 1e3, by_region["steel316"], 1.0 - by_region["steel316"]) for t, by_region in shares.items()]


def interfaces_figure(rows: dict, path: Path) -> None:
    fig, ax = subplots(figsize=(6, 4.5))
    fig.subplots_adjust(**SINGLE_PLOT_MARGINS)
    for case, series in rows.items():
        t, _, far = np.array(series).T
        ax.plot(t, far, label=f"{case.replace('_', ' | ')}: far side")
    ax.set_xlabel("time [ms]")
    ax.set_ylabel("share of the energy beyond the interface")
    ax.set_ylim(0.0, 1.0)
    ax.grid(True, alpha=0.3)
    ax.legend()
    set_title(ax, "Transmission across an interface, struck from the steel side")
    save(fig, path)


def page(out: Path, records: dict, trapping: dict) -> str:
    """The HTML page of the workflow's results."""
    parts = [
        "<!doctype html><html><head><meta charset='utf-8'><title>hexdem: basins and interfaces</title>",
        "<style>body{font-family:sans-serif;max-width:1100px;margin:auto}img{max-width:32%;margin:2px}"
        "pre{background:#f4f4f4;padding:6px}td,th{padding:2px 8px}</style></head><body>",
        "<h1>Basins, interfaces, several strikers and a ring front</h1>",
        "<p>Each case is one <code>hexdem run --movie --config OUT/configs/NAME.toml</code>.</p>",
        "<h2>Energy across the interfaces</h2><img src='interfaces.png' style='max-width:60%'>",
        "<table><tr><th>interface</th><th>far-side share at the end</th><th>largest far-side share</th></tr>",
    ]
    parts += [
        f"<tr><td>{html.escape(case)}</td><td>{t['far_side_fraction_end']:.3f}</td>"
        f"<td>{t['far_side_fraction_max']:.3f}</td></tr>"
        for case, t in trapping.items()
    ]
    parts.append("</table>")
    for case, record in records.items():
        parts += [
            f"<h2>{html.escape(case)}</h2><p>{html.escape(record['what'])}: {record['n_beads']} beads, "
            f"energy drift {record['energy_drift']:.1e}.</p><pre>{html.escape(record['config'])}</pre>"
        ]
        parts += [f"<img src='{case}/{name}' alt='{name}'>" for name in FIGURES if (out / case / name).exists()]
    parts.append("</body></html>")
    return "\n".join(parts)


def run(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, metavar="DIR")
    parser.add_argument("--quick", action="store_true", help="small packings and short runs")
    args = parser.parse_args(argv)
    out = Path(args.out)
    (out / "configs").mkdir(parents=True, exist_ok=True)
    records, started = {}, time.perf_counter()
    for k, (case, (what, text)) in enumerate(CASES.items()):
        path = out / "configs" / f"{case}.toml"
        with atomic_path(path) as tmp:
            tmp.write_text(text.lstrip())
        config = RunConfig.from_dict(tomllib.loads(text), source=str(path)).replace(movie=True)
        config = config.replace(**QUICK[case]) if args.quick else config
        start = time.perf_counter()
        try:
            analysis = run_experiment(config, out / case, log=lambda message: None)
        except HexdemError as error:
            print(f"basins_and_interfaces: error: {case}: {error}", file=sys.stderr)
            return exit_status(error)
        records[case] = {
            "what": what,
            "config": text.strip(),
            "n_beads": len(analysis.model.packing),
            "energy_drift": analysis.results.energy_drift,
            "wall_time_s": time.perf_counter() - start,
            "command": f"hexdem run --movie --config {path} --out {out / case}",
        }
        print(
            f"[{k + 1}/{len(CASES)}] {case}: {records[case]['n_beads']} beads, {records[case]['wall_time_s']:.1f} s",
            file=sys.stderr,
        )
    fractions = {case: side_fractions(out / case) for case in INTERFACES}
    write_csv(
        out / "interfaces.csv",
        INTERFACE_COLUMNS,
        [(case, *row) for case, series in fractions.items() for row in series],
    )
    interfaces_figure(fractions, out / "interfaces.png")
    trapping = {
        case: {
            "far_side_fraction_end": series[-1][2],
            "far_side_fraction_max": max(r[2] for r in series),
            "time_ms_end": series[-1][0],
        }
        for case, series in fractions.items()
    }
    write_json(out / "trapping.json", trapping)
    write_json(
        out / "workflow.json",
        {
            "command": "python workflows/basins_and_interfaces.py " + " ".join(sys.argv[1:] if argv is None else argv),
            "cases": records,
            "wall_time_s": time.perf_counter() - started,
        },
    )
    with atomic_path(out / "index.html") as tmp:
        tmp.write_text(page(out, records, trapping))
    for case, t in trapping.items():
        print(
            f"{case}: {t['far_side_fraction_end']:.3f} of the energy beyond the interface at "
            f"{t['time_ms_end']:.2f} ms (largest {t['far_side_fraction_max']:.3f})",
            file=sys.stderr,
        )
    print(
        f"basins_and_interfaces: {time.perf_counter() - started:.1f} s, results in {out / 'index.html'}",
        file=sys.stderr,
    )
    return 0


if __name__ == "__main__":
    sys.exit(run())
