"""The self-similarity workflow (``--quick``): its files (the late rise's included), and the
physics its measurements must show: Hertz's time scale in the uncompressed pulse, the sound
speed in the linear control; and the pulse-shape analysis on signals built by hand."""

import csv
import html
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from hexdem.analysis.pulse_shape import collapse_residuals, power_law, profiles, pulse_shapes, reference_profile
from hexdem.model.materials import hertz_coefficient, sphere_mass
from hexdem.model.precompression import longitudinal_sound_speed, static_overlap
from hexdem.paper.self_similarity_outputs import COLUMNS

WORKFLOW = Path(__file__).resolve().parents[1] / "workflows" / "self_similarity.py"


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("self_similarity")
    done = subprocess.run(
        [sys.executable, str(WORKFLOW), "--out", str(out), "--quick", "--ranks", "1"],
        cwd=out,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr
    return out


def table(out):
    with open(out / "self_similarity.csv", newline="") as fh:
        assert tuple(next(csv.reader(fh))) == COLUMNS
    with open(out / "self_similarity.csv", newline="") as fh:
        return list(csv.DictReader(fh))


@pytest.mark.slow
def test_the_workflow_writes_its_files(quick):
    rows = table(quick)
    assert {(r["study"], r["line"]) for r in rows} == {
        (s, line) for s in ("uncompressed", "precompressed") for line in ("0", "15", "30")
    }
    result = json.loads((quick / "self_similarity.json").read_text())
    for study in ("uncompressed", "precompressed"):
        for _line, entry in result[study].items():
            for name in ("amplitude_exponent", "width_exponent", "speed_exponent", "energy_exponent"):
                assert set(entry[name]) == {"value", "stderr"} and entry[name]["stderr"] >= 0
            assert len(entry["fit_range_d"]) == 2 and entry["energy_verdict"]
    chain = json.loads((quick / "chain.json").read_text())
    assert {"front_speed_m_s", "nesterenko_speed_m_s", "relative_deviation", "peak_ratio"} <= set(chain)
    rise = json.loads((quick / "late_rise.json").read_text())
    assert set(rise["fits"]) == set(rise["rises"]) == {"baseline", "finer_sampling", "finer_step", "fixed_speed"}
    assert (
        rise["kind"]
        in (
            "no late rise",
            "artefact of the sampling",
            "artefact of the time step",
            "of the half-maximum measure",
            "the front's own",
            "undetermined",
        )
        and rise["verdict"]
    )
    with open(quick / "late_rise.csv", newline="") as fh:
        assert {row["variant"] for row in csv.DictReader(fh)} == set(rise["fits"])
    page = (quick / "self_similarity.html").read_text()
    assert page.count("data:image/png;base64,") == 4 and "self-similar" in page and html.escape(rise["verdict"]) in page


@pytest.mark.slow
def test_the_uncompressed_pulse_keeps_hertzs_time_scale(quick):
    """A Hertz contact's time scale goes as v^(−1/5): a pulse of amplitude v_m ∝ r^a moves at
    c ∝ v_m^(1/5) ∝ r^(a/5). Along the 0° line, the fitted exponents must agree (0.01)."""
    entry = json.loads((quick / "self_similarity.json").read_text())["uncompressed"]["0"]
    a, s = entry["amplitude_exponent"]["value"], entry["speed_exponent"]["value"]
    assert a < 0 and s == pytest.approx(a / 5, abs=0.01)


@pytest.mark.slow
def test_the_linear_controls_front_runs_at_the_sound_speed(quick):
    """The precompressed control's waves are linear; the triangular lattice's long-wave limit is
    isotropic, so on every ray its front moves at c_L = sqrt(9/8) a sqrt(k/m) (k the linearised
    Hertz stiffness at 20 N): the median local speed beyond 12 d within 2 % (the half-maximum
    of a spreading pulse lags the wavefront a little)."""
    d = 0.01905
    coefficient, mass = float(hertz_coefficient(d)), float(sphere_mass(d))
    c_l = longitudinal_sound_speed(20.0, coefficient, mass, d - static_overlap(20.0, coefficient))
    rows = [r for r in table(quick) if r["study"] == "precompressed"]
    for line in ("0", "15", "30"):
        ray = sorted((float(r["distance_d"]), float(r["arrival_time_s"])) for r in rows if r["line"] == line)
        far = np.array([p for p in ray if p[0] > 12.0])
        speeds = np.diff(far[:, 0]) * d / np.diff(far[:, 1])
        assert np.median(speeds) == pytest.approx(c_l, rel=0.02), line


def test_the_pulse_shape_of_a_known_pulse():
    """Pulses v = v_m sech²((t − t0)/T) built by hand: amplitude, arrival (half maximum at
    t0 − T acosh(√2)) and width (2 T acosh(√2)) to the sampling's accuracy, profiles that
    collapse exactly, and a power law fitted exactly."""
    t = np.linspace(0, 10, 4001)
    r = np.array([10.0, 20.0, 40.0, 80.0])
    peak, scale = 2.0 * r**-0.5, 0.3 * r**0.1
    starts = 2.0 + 0.05 * r
    speeds = peak * np.cosh((t[:, None] - starts) / scale) ** -2
    shapes = pulse_shapes(t, speeds)
    half = 2 * scale * math.acosh(math.sqrt(2))
    np.testing.assert_allclose(shapes.peak, peak, rtol=1e-5)
    np.testing.assert_allclose(shapes.width, half, rtol=1e-4)
    np.testing.assert_allclose(shapes.arrival, starts - half / 2, atol=1e-4)
    rows = profiles(t, speeds, shapes)
    assert np.nanmax(collapse_residuals(rows, reference_profile(rows[2:]))) < 1e-3
    for values, exponent in ((peak, -0.5), (scale, 0.1)):
        p, se = power_law(r, values)
        assert p == pytest.approx(exponent, abs=1e-12) and se < 1e-9
