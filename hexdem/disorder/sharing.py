"""Work that two ensembles have in common, done once: the ideal lattice's impacts and the
preparation decks that are the same to the byte.

A study that runs several ensembles (``hexdem paper``: one per disorder strength and
preparation) would otherwise strike the same ideal lattice at the same speed in every one,
and compact the same diameters twice when only the walls' placement after compaction
differs. LAMMPS being deterministic on one rank, a run that is the same is not repeated but
its finished files are copied from the ensemble that has them:

* an ideal impact, when both ensembles' runs at that speed have equal configurations
  (:meth:`~hexdem.disorder.ensemble.EnsembleConfig.run_config`) and the source's
  ``impact.npz`` exists;
* a realization's compaction, when both render the same deck and data file and the
  source's stage is finished (its done marker); then its settling, on the same condition
  (ensembles that differ only in their impacts, such as their friction, share the whole
  preparation).

Copies are made by the ensemble's run, under its lock, before anything runs
(:func:`~hexdem.disorder.runner.run_ensemble`, ``share_from``); it then resumes as if it had
run them itself. Every copy is atomic (a temporary sibling renamed into place), so an
interrupted copy never looks finished.
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

from hexdem.common.io import atomic_directory, atomic_path
from hexdem.disorder.ensemble import Ensemble
from hexdem.disorder.impacts import IMPACT_NAME
from hexdem.disorder.preparation import write_stage_deck
from hexdem.engines.lammps.deck import DATA_NAME, DECK_NAME
from hexdem.engines.lammps.standalone import is_done


def adopt_ideal_impacts(ensemble: Ensemble, source: Ensemble) -> int:
    """Copy ``source``'s finished ideal impacts that ``ensemble`` would run identically; how many."""
    adopted = 0
    for v in ensemble.config.velocities_m_s:
        theirs, ours = source.impact_dir(None, v) / IMPACT_NAME, ensemble.impact_dir(None, v) / IMPACT_NAME
        same = v in source.config.velocities_m_s and source.config.run_config(v) == ensemble.config.run_config(v)
        if same and theirs.exists() and not ours.exists():
            ours.parent.mkdir(parents=True, exist_ok=True)
            with atomic_path(ours) as tmp:
                shutil.copyfile(theirs, tmp)
            adopted += 1
    return adopted


def _same_deck(a: Path, b: Path) -> bool:
    return all((a / name).read_bytes() == (b / name).read_bytes() for name in (DECK_NAME, DATA_NAME))


def _adopt_stage(ensemble: Ensemble, source: Ensemble, k: int, stage: str, scratch: Path) -> bool:
    """Copy ``source``'s finished ``stage`` of realization k if ``ensemble`` would render the
    same deck and data file and has not finished it; whether it was copied."""
    theirs, ours = source.stage_dir(k, stage), ensemble.stage_dir(k, stage)
    if not is_done(theirs) or is_done(ours):
        return False
    rendered = write_stage_deck(
        ensemble.stage_model(k, stage), stage, ensemble.config.preparation, scratch / f"r{k}-{stage}"
    )
    if not _same_deck(rendered, theirs):
        return False
    shutil.rmtree(ours, ignore_errors=True)
    with atomic_directory(ours) as partial:
        shutil.copytree(theirs, partial)
    return True


def adopt_preparation(ensemble: Ensemble, source: Ensemble) -> int:
    """Copy ``source``'s finished preparation stages of every realization whose decks
    ``ensemble`` would render identically, compaction first (the settling deck is rendered
    from the compacted packing, so it is compared only where that is the same); how many."""
    adopted = 0
    with tempfile.TemporaryDirectory(prefix="hexdem-prepare-") as scratch:
        for k in range(min(ensemble.config.realizations, source.config.realizations)):
            adopted += _adopt_stage(ensemble, source, k, "compact", Path(scratch))
            ours, theirs = ensemble.stage_dir(k, "compact"), source.stage_dir(k, "compact")
            if is_done(ours) and is_done(theirs) and _same_deck(ours, theirs):
                adopted += _adopt_stage(ensemble, source, k, "settle", Path(scratch))
    return adopted
