"""The linear-wave study's pieces against what can be worked out by hand: spectra of known
signals, the lattice Fourier sum, a packet's energy moments, the cone's ring and its limits;
then both engines' measured dispersion and conical diffraction against the theory."""

import math

import numpy as np
import pytest

from hexdem.analysis.packet import energy_centroid, energy_spread, ring_radius
from hexdem.analysis.spectrum import band_peaks, branch_signals, peak_frequency, power_spectrum
from hexdem.analysis.wave_recorder import WaveRecorder
from hexdem.engines.sampling import Sample
from hexdem.errors import HexdemError
from hexdem.experiments.wave_run import record_waves
from hexdem.model.config import RunConfig
from hexdem.model.initial_state import read_initial_state, write_initial_state
from hexdem.model.model_builder import build_model, build_packing
from hexdem.model.run_settings import run_settings
from hexdem.theory.conical import CIRCULAR, cone_ring_radius, dirac_matrix
from hexdem.theory.phonons import Lattice2D, cone_slope, sound_speeds
from hexdem.waves.conical import ConicalSettings, measure_conical
from hexdem.waves.dispersion import DispersionSettings, band_spread, measure_dispersion, packing_width, taper
from hexdem.waves.states import bloch_packet, broadband_state

STEEL_20N = Lattice2D.precompressed(20.0, 0.01905)


def test_the_spectral_peaks_of_two_tones_are_their_frequencies():
    """cos(ω1 t) + 0.5 sin(ω2 t), sampled 2000 times: the folded, windowed spectrum peaks at ω1
    and ω2, off the bins, to far below a bin (Hann's main lobe is nearly Gaussian in log)."""
    times = np.arange(2000) * 1e-5
    omegas = np.array([12345.0, 23456.0])
    signals = np.column_stack([np.cos(omegas[0] * times), 0.5 * np.sin(omegas[1] * times + 0.3)])
    omega, power = power_spectrum(times, signals)
    bin_width = omega[1] - omega[0]
    np.testing.assert_allclose(peak_frequency(omega, power), omegas, atol=0.05 * bin_width)


def test_a_complex_signal_is_folded_onto_positive_frequencies():
    """exp(−iωt) has all its power at −ω; folded, its peak is at +ω."""
    times = np.arange(1000) * 1e-5
    omega, power = power_spectrum(times, np.exp(-1j * 20000.0 * times))
    assert peak_frequency(omega, power) == pytest.approx(20000.0, rel=1e-3)


def test_each_band_takes_the_peak_its_polarization_matches():
    """A weak lower-band line at ω1 along e_lower and a twice stronger upper-band line at ω2
    whose polarization is 35° off e_upper: projected on e_lower, the upper line keeps
    4 sin²35° = 1.3 times the lower line's power, so the projection's largest peak is ω2. Each
    bin goes to the band holding the larger share of it (cos²35° = 0.67 at ω2 for the upper
    one), so the lower band is measured at ω1 and the upper one at ω2."""
    times = np.arange(2000) * 1e-5
    omega1, omega2, tilt = 12345.0, 23456.0, math.radians(35.0)
    lower, upper = np.array([1.0, 0.0]), np.array([0.0, 1.0])
    line = np.array([math.sin(tilt), math.cos(tilt)])
    components = np.exp(-1j * omega1 * times)[:, None] * lower + 2 * np.exp(-1j * omega2 * times)[:, None] * line
    polarization = np.column_stack([lower, upper])[None]
    omega, power = power_spectrum(times, branch_signals(components[:, None, :], polarization))
    assert peak_frequency(omega, power)[0, 0] == pytest.approx(omega2, rel=1e-3)  # by projection alone
    np.testing.assert_allclose(band_peaks(omega, power)[0], [omega1, omega2], rtol=1e-3)


def test_the_resolution_of_a_packing_by_hand():
    """A 20-per-edge hexagon is √3 · 19 a wide across its flats. The window is 1 at the centre,
    falls with the distance from it and is 0 from the inscribed circle's rim on. Near Γ the
    bands are ω = c q, so over a disc of radius r about q the spread is c r for each band."""
    config = DispersionSettings(edge_beads=20).config()
    positions = build_model(config).packing.positions_m[: config.n_beads()]
    a = Lattice2D.of(config).spacing_m
    width = packing_width(positions)
    assert width == pytest.approx(math.sqrt(3) * 19 * a, rel=1e-9)
    radius = np.linalg.norm(positions - positions.mean(axis=0), axis=1)
    weights = taper(positions)
    assert weights[np.argmin(radius)] == pytest.approx(1.0, abs=1e-3)
    np.testing.assert_allclose(weights[radius >= width / 2], 0.0, atol=1e-30)
    assert np.all(np.diff(weights[np.argsort(radius)]) <= 1e-12)
    spread = band_spread(STEEL_20N, [[0.01 / STEEL_20N.spacing_m, 0.0]], 0.001 / STEEL_20N.spacing_m)
    np.testing.assert_allclose(
        spread[0], np.array(sound_speeds(STEEL_20N))[::-1] * 0.001 / STEEL_20N.spacing_m, rtol=1e-3
    )


def test_the_recorder_keeps_the_lattice_fourier_sum_and_the_block_energies():
    """Two samples of a 3-bead model split over two 'ranks' (two calls with the beads apart):
    V(q) = Σ v_j exp(−i q·r_j) by hand, and each block's mean ½ m v²."""
    config = RunConfig(shape="sites", sites=[[0, 0], [1, 1], [2, 0]], site_walls_deg=[], duration=1e-4, dump_every=1)
    model = build_model(config)
    settings = run_settings(config, model)
    q = np.array([[30.0, -12.0]])
    recorder = WaveRecorder(model, settings, q, block=2)
    velocities = np.array([[0.1, 0.0], [0.0, -0.2], [0.3, 0.1]])
    for index in (0, 1):
        scaled = velocities * (index + 1)
        recorder(Sample(index, index, 0.0, np.array([1, 3]), np.zeros((2, 2)), scaled[[0, 2]]))
        recorder(Sample(index, index, 0.0, np.array([2]), np.zeros((1, 2)), scaled[[1]]))
    waves = recorder.finish()
    phases = np.exp(-1j * model.packing.positions_m @ q[0])
    np.testing.assert_allclose(waves.components[1, 0], 2 * phases @ velocities)
    kinetic = 0.5 * model.masses_kg[:3] * np.sum(velocities**2, axis=1)
    np.testing.assert_allclose(waves.block_kinetic_j[0], kinetic * (1 + 4) / 2)


def test_a_thin_ring_of_energy_has_its_radius_and_a_shifted_one_its_centroid():
    angle = np.linspace(0, 2 * np.pi, 360, endpoint=False)
    ring = np.column_stack([7.0 * np.cos(angle), 7.0 * np.sin(angle)])
    points = np.vstack([ring, [[0.0, 0.0]]])  # a centre bead without energy
    energies = np.append(np.ones(360), 0.0)[None, :]
    # ⟨r²⟩(0) of a Gaussian of width σ on these points is ~0 for σ → 0: only the centre counts
    assert ring_radius(points, energies, [0.0, 0.0], 1e-3)[0] == pytest.approx(7.0)
    shifted = points + [2.0, -1.0]
    np.testing.assert_allclose(energy_centroid(shifted, energies)[0], [2.0, -1.0], atol=1e-12)
    assert energy_spread(shifted, energies, energy_centroid(shifted, energies))[0] == pytest.approx(7.0)


def test_the_dirac_matrix_has_eigenvalues_one_and_minus_one_and_the_circular_packet_no_drift():
    for angle in np.linspace(0, 2 * np.pi, 13):
        matrix = dirac_matrix(STEEL_20N, angle)
        np.testing.assert_allclose(np.linalg.eigvalsh(matrix), [-1.0, 1.0], atol=1e-6)
        assert abs(np.vdot(CIRCULAR, matrix @ CIRCULAR)) < 1e-6  # ⟨χ|M(θ)|χ⟩ = 0: no direction favoured


def test_the_cone_ring_starts_at_zero_and_grows_at_the_cone_slope():
    """R(0) = 0. Early, R = √2 v_D t: to second order in t the density |∇_q ψ|² is
    |g'|² + 2 v_D² t² g² (the radial term gives v_D² t² |Mχ|² g², the angular one v_D² t² |M'χ|² g²,
    both unit vectors as M² = M'² = I; the cross terms cancel), so ⟨r²⟩ − σ² = 2 v_D² t² (at
    v_D t = 0.03 σ within 1e-3; the next order is (v_D t/σ)²). Far out, the radial part gives
    v_D² t² (its cross terms cancel as ⟨χ|Mχ⟩ = 0) and the angular one, the apex's diffuse interior,
    2σ² ∫ sin²(v_D q t) e^{−σ²q²} dq/q = σ² ln(v_D t/σ) + const: R² − v_D² t² grows by σ² ln 2 per
    doubling of t (1.0010 ln 2 measured from 20 σ to 40 σ), so R/(v_D t) → 1 from above."""
    width, speed = 8 * 0.01905, cone_slope(STEEL_20N)
    assert cone_ring_radius(STEEL_20N, width, [0.0])[0] == pytest.approx(0.0, abs=1e-6 * width)
    early = cone_ring_radius(STEEL_20N, width, [0.03 * width / speed])[0] / (0.03 * width)
    assert early == pytest.approx(math.sqrt(2), rel=1e-3)
    far = cone_ring_radius(STEEL_20N, width, [20 * width / speed, 40 * width / speed], radial_points=4000)
    excess = (far**2 - (np.array([20.0, 40.0]) * width) ** 2) / width**2
    assert excess[1] - excess[0] == pytest.approx(math.log(2), rel=1e-2)
    assert far[1] > 40 * width


def test_a_bloch_packet_at_its_centre_is_all_velocity_along_the_polarization():
    positions = np.array([[0.0, 0.0], [0.3, 0.1]])
    velocities, displacements = bloch_packet(positions, [0.0, 0.0], 1.0, [math.pi / 0.6, 0.0], [0.0, 1.0], 50.0, 2.0)
    np.testing.assert_allclose(velocities[0], 0.0)  # sin 0
    np.testing.assert_allclose(displacements[0], [0.0, 2.0 / 50.0])  # V/ω cos 0
    envelope = math.exp(-0.1 / 2)
    np.testing.assert_allclose(velocities[1], [0.0, 2.0 * envelope * math.sin(math.pi / 2)])


@pytest.mark.parametrize("engine", ["lammps", "reference"])
def test_the_measured_dispersion_lies_on_the_bands(engine, tmp_path):
    """20 per edge under 20 N, random velocities for 10 ms: the spectral peaks along Γ–K–M–Γ
    are within 2 % of the bands (median; measured 0.97 % in both engines), and every point beyond
    the resolution limit |q| = 2 · 2π/L (|q| a = 0.38) within its own bound (the worst 12.5 % at
    |q| a = 0.91 against 22.9 %; without the window and the polarizations, 9.3 % at |q| a = 3.49
    against 5.4 %). The points nearest Γ on Γ–K (|q| a = 0.35) and on M–Γ (0.30) are short of
    the limit."""
    measured = measure_dispersion(
        DispersionSettings(edge_beads=20, duration_s=0.01, points_per_segment=12, engine=engine),
        tmp_path,
        show_progress=False,
    )
    assert measured.median_deviation < 0.02
    assert measured.smallest_resolved_per_m * measured.theory.spacing_m == pytest.approx(
        4 * math.pi / (math.sqrt(3) * 19), rel=1e-6
    )
    assert measured.resolved.tolist() == [False] + [True] * 33 + [False]
    assert measured.within_bound[measured.resolved].all()
    rows = measured.rows()
    assert len(rows) == 2 * (3 * 12 - 1) and rows[0][3] == "lower"  # both Γ left out
    assert [row[8] for row in rows] == (["false"] + ["true"] * 33 + ["false"]) * 2
    assert all(row[9] == "true" for row in rows if row[8] == "true")


def test_a_packet_at_the_dirac_point_opens_into_a_ring_at_the_cone_slope(tmp_path):
    """σ = 8 d to 3σ in the reference engine: the ring's growth rate is v_D within 3 % (measured
    0.06 %), and the control away from K drifts at its group velocity within 2 % and widens by
    less than 10 %. LAMMPS's same packets are the Dirac-point workflow's (tests/test_workflows.py)."""
    packets = measure_conical(
        ConicalSettings(width_d=8.0, reach=3.0, engine="reference"), tmp_path, show_progress=False
    )
    assert packets.slope_deviation < 0.03
    assert packets.drift_deviation < 0.02
    assert packets.control_width_m[-1] / packets.control_width_m[0] < 1.1
    radius = packets.dirac.ring_radius_m()
    assert radius[-1] > 2.5 * packets.dirac.width_m  # it did open


def test_an_initial_state_written_reads_back_bit_for_bit(tmp_path):
    lattice = build_packing(RunConfig(edge_beads=4))
    velocities, displacements = broadband_state(len(lattice), 1e-3, 3), broadband_state(len(lattice), 1e-9, 4)
    write_initial_state(tmp_path / "state.csv", lattice, velocities, displacements)
    state = read_initial_state(tmp_path / "state.csv", lattice)
    assert np.array_equal(state.velocities_m_s, velocities) and np.array_equal(state.displacements_m, displacements)
    with pytest.raises(HexdemError, match=r"needs \(37, 2\) arrays"):
        write_initial_state(tmp_path / "bad.csv", lattice, velocities[:-1])
    assert not (tmp_path / "bad.csv").exists()


def test_two_ranks_record_what_one_rank_records(tmp_path):
    """The same random state in a 12-per-edge precompressed hexagon on 1 and 2 LAMMPS ranks:
    each rank sums over its own beads and the sums merge at the end, so the plane-wave
    components and the energy blocks agree to round-off (the atoms' order differs)."""
    config = RunConfig(edge_beads=12, precompression_n=20.0, v0=1e-6, steps_per_contact=40, duration=2e-3)
    write_initial_state(tmp_path / "state.csv", build_packing(config), broadband_state(config.n_beads(), 5e-4, 2))
    config = config.replace(initial_state_file=str(tmp_path / "state.csv"), dump_every=4)
    q = STEEL_20N.high_symmetry_points()["K"][None, :] * np.array([[0.3], [1.0]])
    one = record_waves(config, tmp_path / "one", q, block=8, show_progress=False)
    two = record_waves(config.replace(ranks=2), tmp_path / "two", q, block=8, show_progress=False)
    scale = np.abs(one.components).max()
    np.testing.assert_allclose(two.components, one.components, rtol=0, atol=1e-9 * scale)
    np.testing.assert_allclose(two.block_kinetic_j, one.block_kinetic_j, rtol=1e-7)


@pytest.mark.parametrize(
    "settings, message",
    [
        (lambda: DispersionSettings(precompression_n=0.0), "precompression_n must be a number > 0"),
        (lambda: DispersionSettings(samples_per_period=2), "samples_per_period must be at least 3"),
        (lambda: DispersionSettings(seed=-1), "seed must be an integer >= 0"),
        (lambda: ConicalSettings(width_d=-2.0), "width_d must be a number > 0"),
        (lambda: ConicalSettings(control_fraction=1.5), "control_fraction must lie between 0 and 1"),
        (lambda: ConicalSettings(width_d=2.0, reach=1.0), "the ring needs at least 4"),
    ],
)
def test_bad_wave_settings_are_one_line(settings, message):
    with pytest.raises(HexdemError, match=message) as caught:
        settings()
    assert "\n" not in str(caught.value)
