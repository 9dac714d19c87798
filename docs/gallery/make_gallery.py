"""Regenerate the gallery: every packing shape and impact kind, run and drawn.

Usage: python docs/gallery/make_gallery.py [NAME ...]   (about a minute on 2 cores; NAME: only
those entries, as ``chain`` or ``dimer``)

Each entry of :data:`ENTRIES` is written to ``configs/<name>.toml``, run with ``hexdem run`` (a
subprocess, as a user would) in a scratch directory, and its peak-speed map (or, where the
front's shape is the point, its arrival map) is copied to ``images/<name>.png``, shrunk for the
page; the frictional entry's spin movie too. ``index.md`` is written last. The docs build reads
these files and runs nothing (``tests/test_docs.py``).
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from PIL import Image

HERE = Path(__file__).resolve().parent
#: Width of the gallery's images [px].
WIDTH = 640
#: Colours of each image's palette (a tenth of the size of full colour, no visible loss).
PALETTE_COLOURS = 128

#: (name, title, what it shows, config, figure of the run shown).
ENTRIES = (
    (
        "hexagon",
        "The experiment: hexagon, velocity impact",
        "The built-in default: the paper's 11-per-edge steel hexagon in delrin walls, bead {0, 0} given 0.4 m/s.",
        "# nothing to set: the built-in default\n",
        "peak_map.png",
    ),
    (
        "striker",
        "The experiment with its striker sphere",
        "The same hexagon struck by a steel sphere through the hole in the wall, as in the experiments.",
        'impact = "striker"\n',
        "peak_map.png",
    ),
    (
        "half_hexagon",
        "Half-hexagon (Fig. 4's packing, smaller)",
        "A half-hexagon of long edge 41 and short edges 21: the front beyond the small hexagon's walls.",
        'shape = "half-hexagon"\nlong_edge = 41\nshort_edge = 21\n',
        "arrival_map.png",
    ),
    (
        "half_disc",
        "Half-disc",
        "The beads within 30 d of the struck bead, only the struck edge's wall: the free arc sends nothing back.",
        'shape = "half-disc"\nradius_beads = 30\n',
        "arrival_map.png",
    ),
    (
        "triangle",
        "Triangular basin",
        "A triangle of 19 per edge struck at the centre of an edge (Hua & Van Gorder's basins).",
        'shape = "triangle"\nedge_beads = 19\n',
        "arrival_map.png",
    ),
    (
        "parallelogram",
        "Parallelogram strip",
        "A strip sheared along +30°: 6 layers of 9 beads, walls on all four sides.",
        'shape = "parallelogram"\nedge_beads = 9\ndepth_beads = 6\n',
        "peak_map.png",
    ),
    (
        "disc",
        "Circular basin in a curved wall",
        "The sites within 10 d of a centre, inside a curved delrin wall (LAMMPS region cylinder).",
        'shape = "disc"\nradius_beads = 10\n',
        "peak_map.png",
    ),
    (
        "sites",
        "Your own packing: listed sites",
        "Ten sites listed by hand, a flat wall behind the struck bead, the rest free.",
        'shape = "sites"\nsites = [[0, 0], [2, 0], [-2, 0], [1, 1], [-1, 1],\n         [0, 2], [2, 2], [-2, 2], '
        "[1, 3], [-1, 3]]\n"
        "site_walls_deg = [0]\n",
        "peak_map.png",
    ),
    (
        "vacancies",
        "Vacancies",
        "The experiment's hexagon with two beads missing on the +30° line (the walls stay).",
        "vacancies = [[4, 4], [6, 6]]\n",
        "peak_map.png",
    ),
    (
        "interface",
        "Materials: an interface and intruders",
        "A steel | brass interface 10 d from the struck edge and two ptfe intruders, struck by a glass sphere.",
        'impact = "striker"\nstriker_material = "glass"\nstriker_diameter_m = 0.012\n\n[[regions]]\nmaterial = '
        '"brass"\n'
        'x_min_d = 10.0\n\n[[regions]]\nmaterial = "ptfe"\nsites = [[0, 4], [2, 6]]\n',
        "peak_map.png",
    ),
    (
        "double_strike",
        "Two impacts: a symmetric double strike",
        "The centres of two opposite edges struck at once: the fronts meet in the middle.",
        "[[impacts]]\nsite = [0, 0]\n\n[[impacts]]\nsite = [0, 20]\nangle_deg = 180.0\n",
        "peak_map.png",
    ),
    (
        "flat_striker",
        "A flat striker on a whole edge",
        "A row of 11 steel spheres at 0.4 m/s on the struck edge: a plane-like excitation.",
        'impact = "striker"\n\n[[impacts]]\nedge_deg = 0.0\n',
        "arrival_map.png",
    ),
    (
        "interior_precompressed",
        "An interior impact in a precompressed hexagon",
        "Bead {0, 14} struck at 0.01 m/s in a hexagon of 15 per edge under 20 N: the ring front of Chong et al.",
        "edge_beads = 15\nprecompression_n = 20.0\n\n[[impacts]]\nsite = [0, 14]\nv0 = 0.01\n",
        "arrival_map.png",
    ),
    (
        "square",
        "Square crystal",
        "15 × 15 steel beads on a square grid in a square basin: the struck row carries a chain's solitary wave "
        "and no other bead moves, the seed paper's contrast to the hexagon.",
        'shape = "square"\nrows = 15\ncolumns = 15\n',
        "peak_map.png",
    ),
    (
        "centered_square",
        "Centered-square crystal with interstitials",
        "A 9 × 12 square of steel beads with a brass interstitial in every cell, sized to touch its four "
        "corners (spherical interstitials, as Szelengowicz et al.'s): the pulse leaks off the struck row through the "
        "interstitials. The run's default length ends before the struck row's wave comes back from the far wall (a "
        "longer run draws that return as the far beads' peaks), so the far corners, which the leak reaches last, are "
        "still rising.",
        'shape = "centered-square"\nrows = 9\ncolumns = 12\ninterstitial_material = "brass"\n',
        "peak_map.png",
    ),
    (
        "chain",
        "A chain with a light intruder",
        "Forty steel beads in a free chain, bead 20 half their diameter: most of the solitary wave passes it, "
        "part comes back.",
        'shape = "chain"\nbeads = 40\nduration = 2e-3\n# bead 20 (counted from 0, the struck one) half the '
        "others' diameter\nintruders = [{bead = 20, diameter_m = 0.009525}]\n",
        "peak_decay.png",
    ),
    (
        "dimer",
        "A dimer chain",
        "Forty steel beads alternating between 19.05 mm and half that diameter (an eighth of the mass), "
        "written as a pattern that repeats: within a few beads the pulse settles into a steady wave, the light "
        "beads (odd n) peaking above the heavy ones, and the free end flies off.",
        'shape = "chain"\nbeads = 40\nduration = 2e-3\n# a pattern that repeats: heavy, light, heavy, light, ...\n'
        "diameters_m = [0.01905, 0.009525]\n",
        "peak_decay.png",
    ),
    (
        "packing",
        "Measured positions: a packing file",
        "Beads read from packing.csv (x, y, diameter in metres and material, one per line; here a hexagon of "
        "8 per edge with five undersized rattlers and five brass beads, written by this script), in flat walls "
        "along the convex hull.",
        'shape = "packing"\npacking_file = "packing.csv"\nwalls = "hull"\nstruck_bead = 3\n',
        "peak_map.png",
    ),
    (
        "random",
        "A random polydisperse disc",
        "Steel beads with diameters uniform in d (1 ± 0.15), packed into a disc of radius 0.15 m by a "
        "LAMMPS compaction (pulled to the centre, then released; `OUT/preparation` keeps its decks and "
        "`packing.csv`) and struck at the middle of the left edge inside walls along its hull: the pulse "
        "follows the force chains. The same seed packs the same disc.",
        'shape = "random"\nradius_m = 0.15\nseed = 1\nwalls = "hull"\n',
        "peak_map.png",
    ),
    (
        "friction",
        "Spheres that rub and roll",
        "The experiment with Coulomb friction μ = 0.3 (Mindlin's tangential force, beads turning); "
        "the movie shows the spin, each bead coloured by its rim's speed.",
        "friction = 0.3\nmovie = true\n",
        "peak_map.png",
    ),
)


def shrink(source: Path, target: Path) -> None:
    with Image.open(source) as image:
        image = image.convert("RGB")
        image.thumbnail((WIDTH, WIDTH * 4))
        image.quantize(colors=PALETTE_COLOURS).save(target, optimize=True)


def write_packing_file(path: Path, seed: int = 1) -> None:
    """A hexagon of 8 per edge written bead by bead, as measured positions would be: five beads
    undersized by 10 % (rattlers that touch no one until the pulse shakes them) and five of brass."""
    import numpy as np

    from hexdem.model.triangular import hexagon

    rng = np.random.default_rng(seed)
    lattice = hexagon(8, 0.01905)
    others = rng.choice(np.setdiff1d(np.arange(len(lattice)), [lattice.struck]), 10, replace=False)
    diameters = lattice.diameters_m.copy()
    diameters[others[:5]] *= 0.9
    materials = np.full(len(lattice), "steel316", dtype=object)
    materials[others[5:]] = "brass"
    rows = [
        f"{x!r},{y!r},{d!r},{m}" for (x, y), d, m in zip(lattice.positions_m.tolist(), diameters.tolist(), materials)
    ]
    path.write_text("x,y,diameter,material\n" + "\n".join(rows) + "\n")


def run_entry(name: str, config: str, figure: str, scratch: Path) -> None:
    path = HERE / "configs" / f"{name}.toml"
    path.write_text(config)
    out = scratch / name
    subprocess.run(["hexdem", "run", "--config", str(path), "--out", str(out)], check=True)
    shrink(out / figure, HERE / "images" / f"{name}.png")
    if (out / "spin_movie.gif").exists():
        shutil.copyfile(out / "spin_movie.gif", HERE / "images" / f"{name}_spin_movie.gif")


def page() -> str:
    lines = [
        "# Gallery",
        "",
        "Every packing shape and impact kind of `hexdem run`, each with its configuration (run it with "
        "`hexdem run --config FILE.toml`) and one of its figures. `docs/gallery/make_gallery.py` "
        "regenerates them.",
        "",
    ]
    for name, title, text, _, figure in ENTRIES:
        lines += [
            f"## {title}",
            "",
            text,
            "",
            f"```{{literalinclude}} configs/{name}.toml",
            ":language: toml",
            "```",
            "",
            f"![{title}: {figure.removesuffix('.png').replace('_', ' ')}](images/{name}.png)",
            "",
        ]
        if (HERE / "images" / f"{name}_spin_movie.gif").exists():
            lines += [f"![{title}: spin movie](images/{name}_spin_movie.gif)", ""]
    lines += ["```{toctree}", ":maxdepth: 1", "", "basins-interfaces-strikers", "```", ""]
    return "\n".join(lines)


def main(names=()) -> int:
    """Run every entry, or those called ``names``, and write the page."""
    unknown = set(names) - {entry[0] for entry in ENTRIES}
    if unknown:
        print(f"make_gallery: no entry {', '.join(sorted(unknown))}", file=sys.stderr)
        return 2
    for folder in ("configs", "images"):
        (HERE / folder).mkdir(exist_ok=True)
    write_packing_file(HERE / "configs" / "packing.csv")
    with tempfile.TemporaryDirectory(prefix="hexdem-gallery-") as scratch:
        for name, _, _, config, figure in (entry for entry in ENTRIES if not names or entry[0] in names):
            print(f"gallery: {name}", file=sys.stderr, flush=True)
            run_entry(name, config, figure, Path(scratch))
    (HERE / "index.md").write_text(page())
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
