"""``hexdem snapshots``: wavefront speed maps at chosen times (Figs. 3 and 4).

Writes ``fig3_smallsim.png/.csv`` (hexagon) or ``fig4_largesim.png/.csv`` (half-hexagon,
with the walls of the 11-per-edge hexagon outlined), ``snapshots.json`` and the LAMMPS run
in ``deck/`` (see :mod:`hexdem.experiments.snapshots`).
"""

from __future__ import annotations

from hexdem.cli.options import add_launcher


def add_arguments(parser) -> None:
    parser.add_argument("--out", metavar="DIR", default="snapshots", help="output directory (default: snapshots/)")
    from hexdem.experiments.snapshots import FIGURE_NAMES

    parser.add_argument(
        "--shape",
        choices=tuple(FIGURE_NAMES),
        default="hexagon",
        help="hexagon (Fig. 3, default) or half-hexagon (Fig. 4)",
    )
    parser.add_argument(
        "--times",
        metavar="T1,T2,...",
        help="snapshot times in ms, rounded to 1 µs (default: 0.15,0.3,...,0.9 for the hexagon, "
        "0.4,0.8,...,2.4 for the half-hexagon)",
    )
    parser.add_argument("--v-striker", type=float, default=0.4, help="striker speed in m/s (default 0.4)")
    parser.add_argument(
        "--ranks",
        type=int,
        default=1,
        metavar="N",
        help="MPI ranks for LAMMPS (default 1, in-process; more run through mpiexec)",
    )
    add_launcher(parser)
    parser.add_argument("--edge-beads", type=int, default=11, help="hexagon: beads per edge (default 11)")
    parser.add_argument("--long-edge", type=int, default=91, help="half-hexagon: beads on the long edge (default 91)")
    parser.add_argument(
        "--short-edge", type=int, default=46, help="half-hexagon: beads on the short edges (default 46)"
    )
    parser.add_argument(
        "--outline-edge",
        type=int,
        metavar="N",
        help="outline the walls of a hexagon with N beads per edge (default: 11 on the half-hexagon)",
    )


def run(args) -> None:
    from hexdem.cli.ensemble import parse_numbers
    from hexdem.experiments.snapshots import DEFAULT_TIMES_MS, run_snapshots
    from hexdem.model.config import RunConfig

    config = RunConfig(
        shape=args.shape,
        edge_beads=args.edge_beads,
        long_edge=args.long_edge,
        short_edge=args.short_edge,
        impact="striker",
        v0=args.v_striker,
        ranks=args.ranks,
        launcher=args.launcher,
    )
    times_ms = (
        DEFAULT_TIMES_MS[args.shape]
        if args.times is None
        else parse_numbers(args.times, "--times", "ms", "0.2,0.4,0.6")
    )
    outline = args.outline_edge if args.outline_edge is not None else (11 if args.shape == "half-hexagon" else None)
    run_snapshots(config, [t * 1e-3 for t in times_ms], args.out, outline_edge=outline or None)
