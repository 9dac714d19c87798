"""How the wavefront turns from hexagonal to circular as it grows, in one command.

    python workflows/front_shape.py --out results/front-shape [--ranks 2] [--edge-beads 100]

Runs ``hexdem run`` (the experiment's steel beads, delrin walls, V0 = 0.4 m/s on the centre
bead of an edge, 0° strike, analysis inside the run, no dump) on a hexagon with
``--edge-beads`` per edge (default 100: 29,701 beads, several minutes on 2 ranks) into
``OUT/hexagon`` and on the half-hexagon of Fig. 4 (long edge 91, short edges 46) into
``OUT/half-hexagon``, each writing its own ``front_shape.csv``. Then it writes
``OUT/front_shape.csv`` (both packings, with a ``packing`` column) and ``OUT/front_shape.png``
(the relative sixfold amplitude of the half-maximum arrival front against its mean radius in
bead diameters: 0 for a circle, 0.058 for a regular hexagon) and ``OUT/workflow.json``.
"""

from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
from record import WorkflowRecord

from hexdem.analysis import figures
from hexdem.analysis.front_shape import FRONT_SHAPE_COLUMNS
from hexdem.common.io import write_csv


def read_shape(path: Path) -> tuple[SimpleNamespace, list[dict]]:
    """The front shape of one run (for the figure) and its table's rows as written."""
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    columns = {key: np.array([float(row[key]) for row in rows]) for key in FRONT_SHAPE_COLUMNS}
    return SimpleNamespace(**columns, mean_radius=columns["mean_radius_d"]), rows


def run(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, metavar="DIR")
    parser.add_argument("--ranks", type=int, default=2, help="MPI ranks per run (default 2)")
    parser.add_argument("--edge-beads", type=int, default=100, help="beads per edge of the hexagon (default 100)")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    configs = {"hexagon": f"shape = \"hexagon\"\nedge_beads = {args.edge_beads}\n",
               "half-hexagon": "shape = \"half-hexagon\"\nlong_edge = 91\nshort_edge = 46\n"}
    record = WorkflowRecord(__file__, argv)
    shapes, rows = {}, []
    for name, text in configs.items():
        (out / f"{name}.toml").write_text(text)
        command = ["run", "--config", str(out / f"{name}.toml"), "--ranks", str(args.ranks), "--out", str(out / name)]
        status = record.run(name, command)
        if status:
            return status
        shape, table = read_shape(out / name / "front_shape.csv")
        label = f"{name}, {'%d per edge' % args.edge_beads if name == 'hexagon' else 'long edge 91, short edges 46'}"
        shapes[label] = shape
        rows += [(name, *(row[key] for key in FRONT_SHAPE_COLUMNS)) for row in table]
    write_csv(out / "front_shape.csv", ("packing", *FRONT_SHAPE_COLUMNS), rows)
    figures.front_shape_figure(shapes, out / "front_shape.png", title="Roundness of the wavefront as it grows")
    record.finish(out)
    return 0


if __name__ == "__main__":
    sys.exit(run())
