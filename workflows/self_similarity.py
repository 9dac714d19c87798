"""Does the decaying pulse become self-similar? The paper's first open question, in one command.

    python workflows/self_similarity.py --out results/self-similarity [--quick] [--ranks 2] [--launcher CMD]

Strikes the front study's half-disc of 170 d (52,599 beads) and its precompressed control, and
follows the leading pulse along the rays at 0°, 15° and 30° from 5 d on
(:mod:`hexdem.paper.self_similarity`); strikes an 80-bead chain and the experiment's hexagon for
the contrast with Nesterenko's solitary wave (:mod:`hexdem.theory.chain_wave`). ``--quick`` (the
test suite's) uses a half-disc of 40 d and a hexagon of 30 per edge. Writes into OUT:
``self_similarity.csv`` (``study,line,n,distance_d,peak_speed,width_s,arrival_time_s,profile_residual``),
``self_similarity.json`` (per study and line the exponents with their standard errors, the fit
range, ``self_similar`` and its criterion, the energy budget), ``chain.json``
(``front_speed_m_s``, ``nesterenko_speed_m_s``, ``relative_deviation``, ``peak_ratio``, ...),
``self_similarity.png``, ``profiles.png``, ``chain.png``; the late rise of the front's anisotropy
measured four ways (:mod:`hexdem.paper.late_rise`: ``late_rise.csv``
``variant,time,mean_radius_d,sixfold_cos``, ``late_rise.json`` with its verdict, ``late_rise.png``);
``self_similarity.html``, the runs' decks under ``runs/`` and ``workflow.json``.
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from hexdem.cli.main import exit_status
from hexdem.cli.options import add_launcher
from hexdem.common.io import ensure_writable_dir, write_csv, write_json
from hexdem.errors import HexdemError
from hexdem.experiments.run import simulate
from hexdem.model.config import RunConfig
from hexdem.paper import late_rise
from hexdem.paper.self_similarity import STUDIES, SelfSimilarityStudy, run_study_packing
from hexdem.paper.self_similarity_outputs import chain_figure, verdict, write_outputs, write_page
from hexdem.theory.chain_wave import CHAIN_LINE, chain_config, measure_chain

#: The striker speed of the chain and of the hexagon beside it [m/s].
V0_M_S = 0.4


def chain_comparison(out: Path, log) -> dict:
    """The chain and the experiment's hexagon, both given V0 on one bead: ``chain.json``'s
    contents, and ``chain.png``."""
    chain_run = simulate(chain_config(V0_M_S), out / "runs" / "chain", log, trace_lines=[CHAIN_LINE])
    hexagon = simulate(RunConfig(v0=V0_M_S), out / "runs" / "hexagon", log).results
    chain = measure_chain(chain_run).as_dict()
    beads = chain_run.results.lines[CHAIN_LINE]
    spacing = {"0": np.sqrt(3.0), "+30": 1.0, "-30": 1.0}
    chain_figure(
        {"chain (80 beads)": (np.arange(len(beads)), chain_run.results.peak_speed[beads] / V0_M_S)},
        {
            f"hexagon, {line}°": (np.arange(len(b)) * spacing[line], hexagon.peak_speed[b] / V0_M_S)
            for line, b in hexagon.lines.items()
            if line in ("0", "+30")
        },
        out / "chain.png",
    )
    return chain


def run(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, metavar="DIR")
    parser.add_argument("--quick", action="store_true", help="a half-disc of 40 d and a hexagon of 30 per edge")
    parser.add_argument("--ranks", type=int, default=2, help="MPI ranks per run (default 2)")
    add_launcher(parser)
    args = parser.parse_args(argv)
    study = SelfSimilarityStudy.quick() if args.quick else SelfSimilarityStudy()
    study = replace(study, front=replace(study.front, ranks=args.ranks, launcher=args.launcher))

    def log(message):
        print(f"self_similarity: {message}", file=sys.stderr, flush=True)

    start = time.perf_counter()
    try:
        out = ensure_writable_dir(args.out)
        measured = {name: run_study_packing(study, name, out / "runs" / name, log) for name in STUDIES}
        chain = chain_comparison(out, log)
        result = write_outputs(out, measured, chain)
        rise = late_rise.run_late_rise(study.front, out / "runs" / "late_rise", log)
        write_csv(out / "late_rise.csv", late_rise.COLUMNS, late_rise.rows(rise))
        rise_verdict = late_rise.verdict(rise)
        write_json(out / "late_rise.json", rise_verdict)
        late_rise.late_rise_figure(rise, out / "late_rise.png")
        write_page(out, result, chain, rise_verdict)
    except HexdemError as exc:
        print(f"self_similarity: error: {exc}", file=sys.stderr)
        return exit_status(exc)
    wall = time.perf_counter() - start
    write_json(
        out / "workflow.json",
        {
            "command": "python workflows/self_similarity.py " + " ".join(sys.argv[1:] if argv is None else argv),
            "wall_time_s": wall,
            "study": study.as_dict(),
        },
    )
    for name in STUDIES:
        log(verdict(result, name))
    log(rise_verdict["verdict"])
    log(f"chain: {100 * chain['relative_deviation']:+.2f} % from Nesterenko's law; {wall:.0f} s in all")
    return 0


if __name__ == "__main__":
    sys.exit(run())
