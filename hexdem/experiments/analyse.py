"""``hexdem analyse``: the result files of a deck that was run by hand, from its dump.

A deck directory written by ``hexdem run`` holds ``in.hexdem``, ``data.hexdem`` and
``hexdem.json`` (its configuration). Rerun by hand (``lmp -in in.hexdem``, on any number of
ranks, by any LAMMPS with the GRANULAR package) it writes ``dump.lammpstrj``;
:func:`analyse_deck` reads that dump through MDAnalysis (:mod:`hexdem.analysis.dump`) and
writes the same result files as ``hexdem run`` (:data:`~hexdem.experiments.run.RESULT_FILES`),
with the definitions of :mod:`hexdem.analysis.peaks`. Unlike hexdem's own runs, this path holds
the whole trajectory in memory. The deck stands alone
(:mod:`hexdem.experiments.deck_config`); a dump of another packing than ``hexdem.json``'s is
refused in one line.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

from hexdem.analysis.dump import read_trajectory
from hexdem.analysis.impact import ImpactAnalysis
from hexdem.common.io import staged_directory
from hexdem.engines.lammps.deck import DUMP_NAME
from hexdem.engines.lammps.runner import log_version
from hexdem.errors import HexdemError
from hexdem.experiments.deck_config import CONFIG_NAME, read_deck_config
from hexdem.experiments.provenance import run_provenance
from hexdem.experiments.run import write_results
from hexdem.model.model_builder import build_model
from hexdem.model.run_settings import run_settings


def analyse_deck(deck_dir, out=None, log=None) -> ImpactAnalysis:
    """Analyse the dump in ``deck_dir`` and write the result files into ``out`` (default: the
    deck's parent directory)."""
    log = log or (lambda message: print(f"hexdem analyse: {message}", file=sys.stderr, flush=True))
    start, provenance = time.perf_counter(), run_provenance()
    deck_dir = Path(deck_dir)
    config = read_deck_config(deck_dir)
    dump = deck_dir / DUMP_NAME
    if not dump.exists():
        raise HexdemError(
            f"{deck_dir} has no {DUMP_NAME}: run the deck by hand first "
            f"(cd {deck_dir} && lmp -in in.hexdem), or use hexdem run --dump"
        )
    model = build_model(config)
    settings = run_settings(config, model)
    log(f"reading {dump} ({settings.n_samples} frames of {model.n_bodies} atoms) through MDAnalysis")
    engine = {
        "name": "lammps",
        "version": log_version(deck_dir / "log.lammps"),
        "ranks": None,
        "wall_time_s": None,
        "deck": str(deck_dir / "in.hexdem"),
    }
    trajectory = read_trajectory(dump, settings, engine)
    atoms = trajectory.velocities_m_s.shape[1]
    if atoms != model.n_bodies:
        raise HexdemError(
            f"{dump} holds {atoms} atoms, the packing of {deck_dir / CONFIG_NAME} {model.n_bodies}: "
            "the dump is another packing's"
        )
    analysis = ImpactAnalysis.from_trajectory(model, settings, trajectory)
    out = Path(out if out is not None else deck_dir.parent)
    with staged_directory(out) as staging:
        write_results(config, analysis, staging, time.perf_counter() - start, provenance, log)
    log(f"energy drift {analysis.results.energy_drift:.2e}; results in {out}")
    return analysis
