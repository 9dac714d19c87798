"""``hexdem sweep``: the plan (products, nested keys, one-line refusals before any run), its
table against the runs' own files and the physics they must show, resuming after an
interruption, and the refusal of another plan in the same directory."""

import json
import os

import numpy as np
import pytest
from conftest import read_csv

from hexdem.cli.main import main
from hexdem.experiments.sweep_plan import Variation, plan_sweep
from hexdem.experiments.sweep_table import SUMMARY_COLUMNS, decay_exponent

SMALL = 'edge_beads = 6\n'
VARY = ["--vary", "friction=0,0.3", "--vary", "v0=0.2,0.4"]


def sweep(tmp_path, *options, base=SMALL):
    config = tmp_path / "base.toml"
    config.write_text(base)
    return main(["sweep", "--config", str(config), *options])


@pytest.fixture(scope="module")
def swept(tmp_path_factory):
    """Two frictions by two speeds of the 6-per-edge hexagon (91 beads), on two workers."""
    root = tmp_path_factory.mktemp("sweep")
    assert sweep(root, *VARY, "--out", str(root / "out"), "--workers", "2") == 0
    return root / "out"


def test_the_table_has_a_row_per_run_in_the_plans_order(swept):
    header, rows = read_csv(swept / "sweep.csv")
    assert header[:3] == ("friction", "v0", "run") and header[3:3 + len(SUMMARY_COLUMNS)] == SUMMARY_COLUMNS
    assert [(float(r["friction"]), float(r["v0"])) for r in rows] == [(0, 0.2), (0, 0.4), (0.3, 0.2), (0.3, 0.4)]
    assert {"energy_share_steel316", "decay_exponent_0", "decay_exponent_+30", "decay_exponent_-30"} <= set(header)
    for row in rows:
        run = swept / row["run"]
        summary = json.loads((run / "summary.json").read_text())
        assert summary["config"]["friction"] == float(row["friction"]) and summary["config"]["v0"] == float(row["v0"])
        assert int(row["n_beads"]) == 91 == summary["lattice"]["n_beads"]
        assert float(row["energy_drift"]) == summary["energy_drift"]
        assert float(row["energy_share_steel316"]) == pytest.approx(1.0, abs=1e-12)  # one material: all of it
    assert (swept / "sweep.png").stat().st_size > 0


def test_the_runs_show_the_physics_they_must(swept):
    """Frictionless spheres lose no energy; Mindlin friction dissipates. Hertz contacts are scale
    invariant (x → λx, t → λ^(−1/4) t), so the decay exponents do not depend on the striker's
    speed, up to the geometric nonlinearity δ/d (1e-3 here) and the sampling."""
    _, rows = read_csv(swept / "sweep.csv")
    by = {(float(r["friction"]), float(r["v0"])): r for r in rows}
    for v0 in (0.2, 0.4):
        assert abs(float(by[0, v0]["energy_lost"])) < 1e-4 < float(by[0.3, v0]["energy_lost"])
        assert float(by[0, v0]["rotational_energy_fraction"]) == 0 < float(by[0.3, v0]["rotational_energy_fraction"])
    for friction in (0, 0.3):
        for line in ("0", "+30"):
            slow, fast = (float(by[friction, v0][f"decay_exponent_{line}"]) for v0 in (0.2, 0.4))
            assert slow > 0 and fast == pytest.approx(slow, rel=2e-3)


def test_the_decay_exponent_of_an_exact_power_law():
    n = np.arange(8)
    assert decay_exponent(n, 3.0 * np.maximum(n, 1) ** -0.75) == pytest.approx(0.75, rel=1e-12)
    assert np.isnan(decay_exponent(np.arange(4), np.ones(4)))  # only n = 2 lies in 2 <= n <= N - 2


def test_a_rerun_resumes_an_interrupted_sweep(swept, tmp_path, capsys):
    """Killed during its third run: the finished runs are kept, the part-written run removed
    and run again, and the table is the uninterrupted sweep's."""
    import shutil

    out = tmp_path / "out"
    shutil.copytree(swept, out)
    _, rows = read_csv(swept / "sweep.csv")
    third = out / rows[2]["run"]
    os.replace(third, third.with_name(f".{third.name}.part"))
    (third.with_name(f".{third.name}.part") / "peaks.csv").unlink()
    kept = {r["run"]: (out / r["run"] / "summary.json").stat().st_mtime_ns for r in rows if r is not rows[2]}
    assert sweep(tmp_path, *VARY, "--out", str(out), "--workers", "2") == 0
    assert "4 runs (3 done before)" in capsys.readouterr().err
    assert {run: (out / run / "summary.json").stat().st_mtime_ns for run in kept} == kept
    assert not list((out / "runs").glob(".*.part"))
    _, again = read_csv(out / "sweep.csv")
    timings = ("engine_wall_time_s", "wall_time_s")
    assert [{k: v for k, v in r.items() if k not in timings} for r in again] == \
        [{k: v for k, v in r.items() if k not in timings} for r in rows]


def test_another_plan_in_the_same_directory_is_refused(swept, tmp_path, capsys):
    assert sweep(tmp_path, "--vary", "friction=0,0.5", "--out", str(swept)) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and "another plan" in lines[0]


@pytest.mark.parametrize("options, message", [
    (["--vary", "frictoin=0,0.1"], "'frictoin' is not a run-config key"),
    (["--vary", "friction"], "expected KEY=V1,V2,..."),
    (["--vary", "friction=0,,0.1"], "no empty value"),
    (["--vary", "friction=0.1,0.1"], "a value is listed twice"),
    (["--vary", "friction=0,-0.2"], "run friction=-0.2: friction must be a coefficient >= 0"),
    (["--vary", "v0=0.4", "--vary", "v0=0.2"], "a key is varied twice"),
    (["--vary", "regions.1.material=brass"], "the base configuration has no item 1"),
    (["--vary", "regions.0.material=unobtainium"], "run regions.0.material=unobtainium"),
    (["--vary", "friction=0", "--workers", "0"], "--workers must be a positive integer"),
])
def test_bad_plans_are_one_line_before_any_run(tmp_path, capsys, options, message):
    base = SMALL + '[[regions]]\nmaterial = "brass"\nx_min_d = 2.0\n'
    assert sweep(tmp_path, *options, "--out", str(tmp_path / "out"), base=base) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], lines
    assert not (tmp_path / "out").exists()


def test_nested_keys_change_one_part_of_a_table_or_list():
    base = {"edge_beads": 4, "regions": [{"material": "brass", "x_min_d": 2.0}], "impacts": [{"site": [0, 0]}]}
    runs = plan_sweep(base, [Variation.parse("regions.0.material=ptfe,glass"), Variation.parse("impacts.0.v0=0.3")])
    assert [run.name for run in runs] == ["regions.0.material=ptfe,impacts.0.v0=0.3",
                                          "regions.0.material=glass,impacts.0.v0=0.3"]
    assert [run.config.regions[0]["material"] for run in runs] == ["ptfe", "glass"]
    assert runs[0].config.impacts[0]["v0"] == 0.3 and base["regions"][0]["material"] == "brass"
