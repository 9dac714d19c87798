"""The disordered packings of a calibration: prepared as the paper prepares them, shared between
parameter sets, and each settled once.

With a prior on :data:`SIGMA_KEY`, the standard deviation σ of the bead diameters [m] (the
ensembles' σ; the paper's is 6 tol = 76.2 µm, tol = 0.0127 mm), or with ``--realizations K`` > 1
(σ then the paper's), every parameter set is simulated on K disordered packings, each prepared
as ``hexdem ensemble`` prepares one (Sec. VI-A, :mod:`hexdem.disorder.preparation`): the lattice
spaced for its largest bead, compacted by 5 N pushes on its edge beads (0.05 N on a square
crystal), the walls placed touching it, settled under the gravity of the 5° tilt; the impact
then runs on the settled packing with that gravity still on.

**Shared deviates.** Packing k's diameters are d_i + σ z_k,i, with z_k standard-normal
deviates drawn by NumPy's default generator seeded with (the calibration's seed, k)
(:func:`deviates`). Every σ scales the same deviates: packing k at two neighbouring σ is one
packing with slightly stronger disorder, so the observables of packing k, and their mean over
the K packings, change smoothly with σ, which is what the emulator interpolates. Independent
draws at every σ would add the spread between packings as noise between neighbouring parameter
sets.

**σ levels.** The σ of every simulated parameter set is one of :data:`SIGMA_LEVELS` values, evenly
spaced in its prior's probability from its lower end to its upper end (:func:`on_sigma_levels`):
the inference's design and posterior draws are moved to the nearest, so that parameter sets share
their packings. The prior's ends are levels, so that the emulators interpolate between simulated
σ and never extrapolate past them; a prior from 0 simulates the ideal lattice, where every packing
is alike.

**Cache.** A preparation depends on the lattice (its shape and size, its nominal diameters),
the beads' and walls' materials, the sensor beads' masses, the diameters (σ, k, the seed), the
preparation's settings and the strike direction (gravity's); not on the impact: its v0,
restitution, friction, time step or duration. It is run elastic and frictionless whatever the
impact's contacts are, as ``hexdem ensemble`` runs it (the drag settles it; at rest, contact
damping and friction carry no load). Its cache key is the SHA-256 of what it runs
(:func:`preparation_key`): the compaction's deck and data file, the settling's walls, gravity
and settings. A settled packing is kept in ``DIR/packings/KEY`` (made in ``.KEY.part`` and
renamed into place, under a lock that a second worker waits on), and every simulation with the
same key reads it instead of settling again.
"""

from __future__ import annotations

import hashlib
import os
import shutil
from dataclasses import asdict, replace
from pathlib import Path

import numpy as np

from hexdem.common.io import file_lock
from hexdem.disorder import stages
from hexdem.disorder.ensemble import ENSEMBLE_SHAPES
from hexdem.disorder.preparation import (
    CRYSTAL_PUSH_FORCE_N,
    SIGMA_PER_TOLERANCE,
    TOLERANCE_M,
    Disorder,
    Preparation,
    write_stage_deck,
)
from hexdem.disorder.stages import compaction_model, prepare
from hexdem.engines.lammps.deck import DATA_NAME, DECK_NAME, walls_block
from hexdem.errors import HexdemError
from hexdem.model.config import RunConfig
from hexdem.model.contact_law import NO_FRICTION
from hexdem.model.granular import GranularModel
from hexdem.model.model_builder import build_model
from hexdem.model.packing import Packing
from hexdem.model.units import SI

#: The prior key of the disorder: the standard deviation of the bead diameters [m].
SIGMA_KEY = "diameter_sigma_m"
#: σ when it is not calibrated but packings are (``--realizations K`` > 1): the paper's 6 tol.
PAPER_SIGMA_M = SIGMA_PER_TOLERANCE * TOLERANCE_M
#: Packings per parameter set when σ is calibrated and ``--realizations`` is not given.
DISORDER_REALIZATIONS = 8
#: The values σ takes in the simulated parameter sets (see the module docstring).
SIGMA_LEVELS = 10
PACKINGS = "packings"


def deviates(seed: int, realization: int, n_beads: int) -> np.ndarray:
    """z_k: the (n_beads,) standard-normal deviates of packing ``realization``."""
    return np.random.default_rng([int(seed), int(realization)]).standard_normal(int(n_beads))


def on_sigma_levels(unit_points, column: int) -> np.ndarray:
    """``unit_points`` with their σ coordinate (``column``) moved to the nearest of
    :data:`SIGMA_LEVELS` levels evenly spaced in probability from the prior's lower end to its upper
    end (unit coordinates i / (SIGMA_LEVELS − 1))."""
    points = np.array(unit_points, float)
    points[:, column] = np.round(points[:, column] * (SIGMA_LEVELS - 1)) / (SIGMA_LEVELS - 1)
    return points


def preparation_of(config: RunConfig) -> Preparation:
    """The paper's preparation of ``config``'s lattice: 5 N pushes on a hexagon, 0.05 N on a
    square crystal (:mod:`hexdem.disorder.preparation`)."""
    return Preparation() if config.shape == "hexagon" else Preparation(push_force_n=CRYSTAL_PUSH_FORCE_N)


def check_disorderable(config: RunConfig, sigma_max_m: float, realizations: int, seed: int) -> None:
    """Refuse, in one line, a lattice that the preparation does not build and a σ at which a
    packing would hold a bead of no positive diameter."""
    if config.shape not in ENSEMBLE_SHAPES:
        raise HexdemError(
            f"--config: disordered packings are prepared on the shapes {', '.join(ENSEMBLE_SHAPES)}, "
            f"not {config.shape!r}"
        )
    nominal = build_model(config).packing.diameters_m
    for k in range(realizations):
        smallest = float(np.min(nominal + sigma_max_m * deviates(seed, k, len(nominal))))
        if smallest <= 0:
            raise HexdemError(
                f"--prior {SIGMA_KEY}: at sigma = {sigma_max_m:.6g} m packing {k} would hold a bead "
                f"of diameter {smallest:.3g} m; lower the prior's upper end"
            )


def preparation_model(model: GranularModel) -> GranularModel:
    """``model`` as its packing is prepared: elastic and frictionless (see the module docstring)."""
    return replace(model, restitution=1.0, wall_restitution=1.0, friction=NO_FRICTION)


def _compaction(model: GranularModel, sigma_m: float, seed: int, realization: int) -> GranularModel:
    ideal = model.packing
    diameters = ideal.diameters_m + sigma_m * deviates(seed, realization, len(ideal))
    return compaction_model(model, ideal, diameters, Disorder(ideal.diameter_m, sigma_m=sigma_m))


def preparation_key(compact_deck: Path, model: GranularModel, preparation: Preparation) -> str:
    """The SHA-256 of everything a preparation runs (see the module docstring): the rendered
    compaction deck ``compact_deck``, and the walls, gravity and settings of its settling."""
    digest = hashlib.sha256()
    for name in (DECK_NAME, DATA_NAME):
        digest.update((compact_deck / name).read_bytes())
    digest.update(walls_block(model, SI).encode())
    digest.update(repr(preparation.gravity_vector_m_s2(model.impact.direction).tolist()).encode())
    digest.update(repr(sorted(asdict(preparation).items())).encode())
    return digest.hexdigest()


def settled_packing(
    nominal: GranularModel, preparation: Preparation, sigma_m: float, seed: int, realization: int, root
) -> tuple[Packing, np.ndarray]:
    """(packing ``realization`` of the lattice of the model ``nominal`` at σ = ``sigma_m`` settled by
    ``preparation`` (:func:`preparation_of`), with its walls; the gravity it settled under [m/s²]),
    prepared in ``root``/KEY or read from there."""
    root = Path(root)
    root.mkdir(parents=True, exist_ok=True)
    model = preparation_model(nominal)
    compaction = _compaction(model, sigma_m, seed, realization)
    scratch = root / f".render-{os.getpid()}"
    shutil.rmtree(scratch, ignore_errors=True)
    try:
        key = preparation_key(write_stage_deck(compaction, "compact", preparation, scratch), model, preparation)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    folder = root / key[:24]
    with file_lock(root / f".{folder.name}.lock"):
        if not folder.is_dir():
            prepare(model, compaction, preparation, folder)
    packing = stages.settled_packing(model, model.packing, folder, preparation, str(folder))
    return packing, preparation.gravity_vector_m_s2(model.impact.direction)
