"""What ``hexdem paper`` computes: the full paper, or ``--quick`` (thinned).

Both run the same code paths; ``--quick`` only thins them (fewer V₀, realizations, σ and μ,
smaller packings), so that it checks the whole pipeline at a fraction of the cost. Its numbers
are rough.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

from hexdem.common.checks import positive_int
from hexdem.disorder.ensemble import check_impact_steps
from hexdem.disorder.preparation import TOLERANCE_M
from hexdem.model.config import STEPS_PER_CONTACT

#: Disorder strengths σ / tol of the disorder study (the paper's is 6), and the quick run's.
SIGMA_PER_TOL = (0.0, 1.0, 2.0, 3.0, 6.0)
QUICK_SIGMA_PER_TOL = (0.0, 1.0, 6.0)
#: Striker speed of the disorder study [m/s] and those of Fig. 9 (σ = 6 tol).
STUDY_VELOCITY_M_S = 0.40
FIG9_VELOCITIES_M_S = (0.25, 0.40, 0.70)
#: σ / tol of the crossover sweep (:mod:`hexdem.paper.crossover`): log-spaced from 1e-3 tol (13 nm,
#: a hundredth of the static overlaps' scale) to the paper's 6 tol, across the impact's overlap
#: δ(V) = 0.53, 0.77 and 1.20 tol at 0.25, 0.40 and 0.70 m/s; the quick run's is coarse, with
#: the five σ > 0 that the crossover's four-parameter fit needs (:func:`~hexdem.paper.crossover.fit_crossover`).
CROSSOVER_SIGMA_PER_TOL = (0.001, 0.003, 0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 6.0)
QUICK_CROSSOVER_SIGMA_PER_TOL = (0.001, 0.01, 0.1, 1.0, 6.0)
#: Striker speeds of the crossover sweep [m/s]: every prestressed ensemble is struck at these.
CROSSOVER_VELOCITIES_M_S = FIG9_VELOCITIES_M_S
#: Packings of the full run's friction study (:mod:`hexdem.paper.friction_study`).
FULL_FRICTION_REALIZATIONS = 5
#: Coulomb μ of the friction study's frictional runs (μ = 0 is the paper's ensemble itself), and
#: the quick run's.
FRICTIONS = (0.1, 0.2, 0.5)
QUICK_FRICTIONS = (0.5,)
#: Beads per edge of the ensembles' hexagon: the experiment's, and the quick run's smaller one.
ENSEMBLE_EDGE_BEADS = 11
QUICK_ENSEMBLE_EDGE_BEADS = 7
#: σ / tol at which the preparation is also run without prestress.
RELAXED_SIGMA_PER_TOL = (0.0, 6.0)
#: Slack of the walls in the preparation without prestress [m]: one diameter tolerance,
#: twice the compaction's total shrinkage across the 21-bead hexagon (about 6 µm).
RELAXED_WALL_SLACK_M = TOLERANCE_M


@dataclass(frozen=True)
class PaperSettings:
    """``quick``: the thinned variant; ``workers``: processes (the studies' runs, MPI ranks of
    Fig. 4) at once; ``launcher``: the MPI launcher command that starts them
    (None: this environment's ``mpiexec``); ``parsl``: a Parsl configuration file that takes
    the runs of the studies (the scaling sweep, the ensembles' impacts) instead of local
    processes (:mod:`hexdem.experiments.executors`; :func:`~hexdem.paper.pipeline.run_paper`
    runs it);
    ``steps_per_contact`` the time step of the LAMMPS impacts (snapshots, ensembles), τ/this:
    the sweep keeps its own 140 (:class:`~hexdem.theory.sweep.SweepSettings`).

    ``n_v0`` V₀ values of the scaling sweep (0.01 … 0.30); ``realizations`` per disordered
    ensemble (σ = 0 needs one: equal beads prepared the same way are identical);
    ``half_hexagon`` (long, short) edges of Fig. 4's packing; ``sigma_per_tol`` the σ / tol of
    the disorder study and ``crossover_sigma_per_tol`` those of the crossover sweep;
    ``frictions`` the friction study's μ; ``ensemble_edge_beads`` the ensembles' hexagon.
    """

    quick: bool = False
    workers: int = 2
    launcher: str | None = None
    parsl: str | None = None
    steps_per_contact: int = STEPS_PER_CONTACT

    def __post_init__(self):
        positive_int("--workers", self.workers)
        check_impact_steps("--steps-per-contact", self.steps_per_contact)

    @property
    def n_v0(self) -> int:
        """Six in the quick run: one more than the fit-protocol search's fewest V₀ a range
        (:data:`~hexdem.theory.protocols.MIN_V0`), so that it still chooses among ranges."""
        return 6 if self.quick else 30

    @property
    def realizations(self) -> int:
        return 2 if self.quick else 20

    @property
    def friction_realizations(self) -> int:
        """Packings of the friction study: the first of the σ = 6 tol ensemble's, fewer than its
        realizations so that the whole paper stays within ten minutes on two workers."""
        return 2 if self.quick else FULL_FRICTION_REALIZATIONS

    @property
    def sigma_per_tol(self) -> tuple[float, ...]:
        return QUICK_SIGMA_PER_TOL if self.quick else SIGMA_PER_TOL

    @property
    def crossover_sigma_per_tol(self) -> tuple[float, ...]:
        return QUICK_CROSSOVER_SIGMA_PER_TOL if self.quick else CROSSOVER_SIGMA_PER_TOL

    @property
    def frictions(self) -> tuple[float, ...]:
        return QUICK_FRICTIONS if self.quick else FRICTIONS

    @property
    def ensemble_edge_beads(self) -> int:
        return QUICK_ENSEMBLE_EDGE_BEADS if self.quick else ENSEMBLE_EDGE_BEADS

    @property
    def half_hexagon(self) -> tuple[int, int]:
        return (41, 21) if self.quick else (91, 46)

    def identity(self) -> dict:
        """What the results depend on (not the number of workers, the launcher nor Parsl)."""
        return {"quick": self.quick, "steps_per_contact": self.steps_per_contact}

    def as_dict(self) -> dict:
        return {
            **asdict(self),
            "n_v0": self.n_v0,
            "realizations": self.realizations,
            "half_hexagon": list(self.half_hexagon),
            "sigma_per_tol": list(self.sigma_per_tol),
            "study_velocity_m_s": STUDY_VELOCITY_M_S,
            "fig9_velocities_m_s": list(FIG9_VELOCITIES_M_S),
            "relaxed_sigma_per_tol": list(RELAXED_SIGMA_PER_TOL),
            "relaxed_wall_slack_m": RELAXED_WALL_SLACK_M,
            "crossover_sigma_per_tol": list(self.crossover_sigma_per_tol),
            "crossover_velocities_m_s": list(CROSSOVER_VELOCITIES_M_S),
            "friction_realizations": self.friction_realizations,
            "frictions": list(self.frictions),
            "ensemble_edge_beads": self.ensemble_edge_beads,
        }
