"""Ensembles of weakly disordered packings struck by a striker sphere (Sec. VI; Figs. 8, 9).

Every realization k is prepared as in Sec. VI-A (:mod:`hexdem.disorder.preparation`: diameters from
(seed, k), compaction by 5 N edge forces, walls, gravity settle) once, and its settled
packing is struck at every velocity of the ensemble. The ideal lattice (equal diameters,
no gravity, as in the paper's ideal simulations) is struck by the same striker for
reference. Striker: steel, nominal diameter, touching the edge-centre bead at t = 0 and
entering through the hole in the wall.

**Running.** Three phases, compact → settle → impacts, each running all its pending decks,
every deck one task of the study executor (:mod:`hexdem.experiments.executors`): ``workers``
local processes, or Parsl across machines. An impact is analysed while it runs, and a
realization's result assembled as soon as its last impact finishes.

**Resuming.** A deck is finished when it has its done marker; a realization when its
``result.npz`` exists (written atomically once all its impacts are analysed; the dumps are
then deleted unless ``keep_dumps``). A rerun with the same parameters skips both and redoes
only what is missing; nothing half-written is ever read. More realizations can be added
later: realization k does not depend on how many there are.

**Determinism.** The same seed gives the same diameters and, LAMMPS being deterministic
on one rank, bit-identical results, however many workers share the work.

**Layout of OUT**: ``ensemble.json`` (parameters, timings, disorder effect),
``realizations/r0007/{compact,settle,v0.400,...}/`` decks and ``result.npz``,
``ideal/v0.400/`` decks and ``ideal/result.npz``, and the tables and figures of
:func:`hexdem.disorder.stats.write_statistics`.
"""

from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from hexdem.common.checks import is_number, positive_int
from hexdem.disorder.preparation import Disorder, Preparation
from hexdem.disorder.stages import compaction_model, settled_packing, settling_model
from hexdem.errors import HexdemError
from hexdem.model.config import MIN_STEPS_PER_CONTACT, STEPS_PER_CONTACT, RunConfig
from hexdem.model.contact_law import NO_FRICTION
from hexdem.model.granular import GranularModel, RunSettings
from hexdem.model.model_builder import build_model, build_packing
from hexdem.model.packing import Packing
from hexdem.model.run_settings import run_settings

RESULT_NAME = "result.npz"
MANIFEST_NAME = "ensemble.json"
#: An impact is sampled this many times per contact time (every 10 steps of the default τ/140).
IMPACT_SAMPLES_PER_CONTACT = 14
#: The packings an ensemble can be built on.
ENSEMBLE_SHAPES = ("hexagon", "square", "centered-square")
#: The shape keys of an ensemble and their values in ensembles made before they existed.
SHAPE_DEFAULTS = {"shape": "hexagon", "rows": 15, "columns": 15}
#: Progress-bar labels of the phases.
PHASE_LABELS = {"compact": "compacting", "settle": "settling", "impacts": "impacts"}


def check_impact_steps(name: str, steps_per_contact) -> int:
    """``steps_per_contact`` of an ensemble's impacts: at least the run's minimum, and a multiple
    of :data:`IMPACT_SAMPLES_PER_CONTACT` (they are sampled every τ/that); ``name`` is the
    option or key the value came from."""
    positive_int(name, steps_per_contact)
    if steps_per_contact < MIN_STEPS_PER_CONTACT or steps_per_contact % IMPACT_SAMPLES_PER_CONTACT:
        raise HexdemError(
            f"{name} of the ensembles' impacts must be a multiple of {IMPACT_SAMPLES_PER_CONTACT} "
            f"of at least {MIN_STEPS_PER_CONTACT} (they are sampled every 1/{IMPACT_SAMPLES_PER_CONTACT} "
            f"of the contact time), got {steps_per_contact}"
        )
    return steps_per_contact


@dataclass(frozen=True)
class EnsembleConfig:
    """An ensemble: ``realizations`` packings of ``shape`` (:data:`ENSEMBLE_SHAPES`): a hexagon with
    ``edge_beads`` per edge, or a square or centered-square crystal of ``rows`` × ``columns``
    (:mod:`hexdem.model.square_crystals`), each struck at every striker speed of
    ``velocities_m_s`` [m/s].

    ``seed`` seeds every realization's diameters; ``disorder`` and ``preparation`` are Sec.
    VI-A; ``steps_per_contact`` the impacts' time step, τ/this (τ the two-bead Hertz contact
    time at the striker speed; see :class:`~hexdem.model.config.RunConfig`); the impacts are
    sampled every τ/:data:`IMPACT_SAMPLES_PER_CONTACT` (5 µs at 0.4 m/s: peaks within 1e-4 and arrival
    times within 3 ns of every-other-step sampling); ``duration_s`` run length [s]
    (None: the ideal crossing estimate of :class:`~hexdem.model.config.RunConfig` times
    ``duration_factor``: 1.5 lets the slower disordered wave reach the lines' far beads,
    while the far wall's reflection has not yet changed the ideal lattice's peaks, which it
    does at 1.75); ``reference_bead`` {m, n} the bead whose arrival is t = 0 in the maps
    (Fig. 8's white x; default {0, 2}: bead 1 of the 0° line, the sensor nearest the impact, on
    the hexagon and the centered square; bead 2 on the square, whose labels are row and column);
    ``friction`` Coulomb's μ of the impacts' contacts, beads and walls alike
    (:mod:`hexdem.model.contact_law`; 0: the paper's frictionless spheres). The preparation is
    frictionless whatever ``friction`` is: every ensemble of the same diameters starts its
    impacts from the same settled packing, whose contacts carry no tangential load.
    """

    realizations: int = 20
    velocities_m_s: tuple[float, ...] = (0.25, 0.40, 0.70)
    seed: int = 0
    edge_beads: int = 11
    disorder: Disorder = field(default_factory=lambda: Disorder(RunConfig().diameter_m))
    preparation: Preparation = field(default_factory=Preparation)
    steps_per_contact: int = STEPS_PER_CONTACT
    duration_s: float | None = None
    duration_factor: float = 1.5
    reference_bead: tuple[int, int] = (0, 2)
    friction: float = 0.0
    shape: str = "hexagon"
    rows: int = 15
    columns: int = 15

    def __post_init__(self):
        positive_int("the number of realizations", self.realizations)
        if self.shape not in ENSEMBLE_SHAPES:
            raise HexdemError(f"ensembles are built on shape {', '.join(ENSEMBLE_SHAPES)}, not {self.shape!r}")
        check_impact_steps("steps_per_contact", self.steps_per_contact)
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or self.seed < 0:
            raise HexdemError(f"the seed must be a non-negative integer, got {self.seed!r}")
        speeds = tuple(self.velocities_m_s)
        if not speeds or len(set(speeds)) != len(speeds) or not all(is_number(v) and v > 0 for v in speeds):
            raise HexdemError(f"striker velocities must be distinct positive speeds in m/s, got {speeds!r}")
        object.__setattr__(self, "velocities_m_s", tuple(float(v) for v in speeds))
        if self.duration_s is not None and not (is_number(self.duration_s) and self.duration_s > 0):
            raise HexdemError(f"duration must be a positive time in s, got {self.duration_s!r}")
        if not (is_number(self.duration_factor) and self.duration_factor >= 1):
            raise HexdemError(f"duration_factor must be >= 1, got {self.duration_factor!r}")
        ideal = self.ideal_lattice()
        if ideal.index_of(*self.reference_bead) is None:
            raise HexdemError(
                f"reference bead {{{self.reference_bead[0]}, {self.reference_bead[1]}}} is not in the {ideal.shape}"
            )

    def striker_run(self, v_striker: float) -> tuple[RunConfig, GranularModel]:
        """The ideal-lattice striker run at ``v_striker`` (also sets every run's dt and length) and its
        model, built once (the model does not depend on the run's duration)."""
        size = (
            {"edge_beads": self.edge_beads} if self.shape == "hexagon" else {"rows": self.rows, "columns": self.columns}
        )
        base = RunConfig(
            shape=self.shape,
            **size,
            diameter_m=self.disorder.diameter_m,
            impact="striker",
            v0=float(v_striker),
            steps_per_contact=self.steps_per_contact,
            dump_every=self.steps_per_contact // IMPACT_SAMPLES_PER_CONTACT,
            friction=self.friction,
        )
        model = build_model(base)
        duration = (
            self.duration_s
            if self.duration_s is not None
            else self.duration_factor * run_settings(base, model).duration_s
        )
        return base.replace(duration=duration), model

    def run_config(self, v_striker: float) -> RunConfig:
        """The ideal-lattice striker run at ``v_striker`` (:meth:`striker_run`)."""
        return self.striker_run(v_striker)[0]

    def ideal_lattice(self) -> Packing:
        return build_packing(self.run_config(self.velocities_m_s[0]))

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)

    def identity(self) -> dict:
        """Everything that determines a realization's results: all but the number of
        realizations and the preparation's step limit (which only decides whether a stage
        that has not settled yet goes on)."""
        return self.identity_of(self.as_dict())

    @staticmethod
    def identity_of(config: dict) -> dict:
        identity = json.loads(json.dumps(config))
        del identity["realizations"], identity["preparation"]["max_steps"]
        identity.setdefault("friction", 0.0)  # ensembles run before friction existed were frictionless
        for name, default in SHAPE_DEFAULTS.items():  # and before other shapes, hexagons
            identity.setdefault(name, default)
        return identity


def velocity_name(v: float) -> str:
    """Directory and figure suffix of striker speed ``v`` [m/s], e.g. ``v0.400``."""
    return f"v{v:.3f}"


class Ensemble:
    """An ensemble directory: where each deck and result lives, and the models behind them."""

    def __init__(self, config: EnsembleConfig, out):
        self.config, self.out = config, Path(out)
        self._runs: dict[float, tuple[RunConfig, GranularModel]] = {}
        run, model = self.striker_run(config.velocities_m_s[0])
        self.ideal = build_packing(run)
        self._base_model = replace(model, friction=NO_FRICTION)

    # ---- layout
    def realization_dir(self, k: int) -> Path:
        return self.out / "realizations" / f"r{k:04d}"

    def stage_dir(self, k: int, stage: str) -> Path:
        return self.realization_dir(k) / stage

    def impact_dir(self, k: int | None, v: float) -> Path:
        """The impact deck of realization k (None: the ideal lattice) at striker speed ``v``."""
        return (self.out / "ideal" if k is None else self.realization_dir(k)) / velocity_name(v)

    def result_path(self, k: int | None) -> Path:
        """``result.npz`` of realization k (None: the ideal lattice)."""
        return self.out / "ideal" / RESULT_NAME if k is None else self.realization_dir(k) / RESULT_NAME

    def impact_dirs(self, k: int | None) -> list[Path]:
        """The impact decks of realization k (None: the ideal lattice), one per velocity."""
        return [self.impact_dir(k, v) for v in self.config.velocities_m_s]

    # ---- models
    def striker_run(self, v: float) -> tuple[RunConfig, GranularModel]:
        """:meth:`EnsembleConfig.striker_run`, built once per striker speed ``v``."""
        if v not in self._runs:
            self._runs[v] = self.config.striker_run(v)
        return self._runs[v]

    def impact(self, k: int | None, v: float) -> tuple[GranularModel, RunSettings]:
        """The model of realization k (None: the ideal lattice) struck at ``v`` and the run's settings
        (time step and length, from the ideal lattice's model)."""
        config, model = self.striker_run(v)
        settings = run_settings(config, model)
        return (model if k is None else replace(model, packing=self.settled_packing(k))), settings

    def diameters_m(self, k: int) -> np.ndarray:
        """Realization k's diameters: each bead's nominal one (d, or a centered square's
        interstitial size) plus its draw's deviation from d."""
        draws = self.config.disorder.diameters_m(len(self.ideal), self.config.seed, k)
        return draws + (self.ideal.diameters_m - self.ideal.diameter_m)

    def stage_model(self, k: int, stage: str) -> GranularModel:
        """The packing a preparation stage starts from: spaced (compact) or compacted with walls
        (settle; the walls touch it, or stand back by the preparation's slack)."""
        if stage == "compact":
            return compaction_model(self._base_model, self.ideal, self.diameters_m(k), self.config.disorder)
        return settling_model(
            self._base_model, self.ideal, self.realization_dir(k), self.config.preparation, *self._settling_names(k)
        )

    def settled_packing(self, k: int) -> Packing:
        """The settled packing of realization k, with the walls placed after compaction."""
        return settled_packing(
            self._base_model, self.ideal, self.realization_dir(k), self.config.preparation, *self._settling_names(k)
        )

    @staticmethod
    def _settling_names(k: int) -> tuple[str, str]:
        return f"realization {k}", "; rerun with a larger --max-settle-steps"

    def impact_model(self, k: int | None, v: float) -> GranularModel:
        """Realization k (None: the ideal lattice) struck at ``v``."""
        return self.impact(k, v)[0]

    @property
    def gravity_m_s2(self) -> np.ndarray:
        return self.config.preparation.gravity_vector_m_s2(self._base_model.impact.direction)
