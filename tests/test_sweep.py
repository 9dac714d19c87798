"""``hexdem sweep``: the plan (products, nested keys, one-line refusals before any run), its
table against the runs' own files and the physics they must show, resuming after an
interruption, and the refusal of another plan in the same directory."""

import json
import os

import numpy as np
import pytest
from conftest import read_csv

from hexdem.cli.main import main
from hexdem.errors import HexdemError
from hexdem.experiments.sweep_plan import Variation, plan_sweep
from hexdem.experiments.sweep_table import SUMMARY_COLUMNS, decay_exponent

#: A steel | brass interface across the 6-per-edge hexagon (91 beads), 3 d from the struck edge.
SMALL = 'edge_beads = 6\nduration = 3e-3\n[[regions]]\nmaterial = "brass"\nx_min_d = 3.0\n'
VARY = ["--vary", "regions.0.material=brass,ptfe", "--vary", "v0=0.2,0.4"]
PLAN = [("brass", 0.2), ("brass", 0.4), ("ptfe", 0.2), ("ptfe", 0.4)]


def sweep(tmp_path, *options, base=SMALL):
    config = tmp_path / "base.toml"
    config.write_text(base)
    return main(["sweep", "--config", str(config), *options])


@pytest.fixture(scope="module")
def swept(tmp_path_factory):
    """The interface's material (brass, ptfe) by the speed (0.2, 0.4 m/s), on two workers."""
    root = tmp_path_factory.mktemp("sweep")
    assert sweep(root, *VARY, "--out", str(root / "out"), "--workers", "2") == 0
    return root / "out"


def test_the_table_has_a_row_per_run_in_the_plans_order(swept):
    header, rows = read_csv(swept / "sweep.csv")
    assert header[:5] == ("regions.0.material", "v0", "run", "status", "warnings") and header[-1] == "error"
    assert header[5 : 5 + len(SUMMARY_COLUMNS)] == SUMMARY_COLUMNS
    assert {(row["status"], row["warnings"], row["error"]) for row in rows} == {("done", "", "")}
    assert [(r["regions.0.material"], float(r["v0"])) for r in rows] == PLAN
    assert {
        "energy_share_steel316",
        "energy_share_brass",
        "energy_share_ptfe",
        "decay_exponent_0",
        "decay_exponent_+30",
        "decay_exponent_-30",
    } <= set(header)
    for row in rows:
        summary = json.loads((swept / row["run"] / "summary.json").read_text())
        assert summary["config"]["regions"][0]["material"] == row["regions.0.material"]
        assert summary["config"]["v0"] == float(row["v0"]) and int(row["n_beads"]) == 91
        assert float(row["energy_drift"]) == summary["energy_drift"]
        other = "ptfe" if row["regions.0.material"] == "brass" else "brass"
        assert row[f"energy_share_{other}"] == ""  # not a region of this run
        shares = float(row["energy_share_steel316"]) + float(row[f"energy_share_{row['regions.0.material']}"])
        assert shares == pytest.approx(1.0, rel=1e-12)
    assert (swept / "sweep.png").stat().st_size > 0


def test_runs_that_warned_are_named_in_the_table_the_figure_and_the_last_line(tmp_path, capsys, monkeypatch):
    """A run cut short before its wave crossed the packing warns on its own (far_wall_reached
    false); in a study its warning goes into the table's warnings column, is ringed in sweep.png,
    and the command ends by naming it. The energy panel is the audit's drift on a log axis that
    holds the round-off floor and the threshold that fails a run."""
    from hexdem.analysis import plotting as plots
    from hexdem.analysis.energy import ROUND_OFF
    from hexdem.experiments.run import MAX_ENERGY_DRIFT

    drawn = []
    monkeypatch.setattr(plots, "save", lambda fig, path: drawn.append(fig))
    out = tmp_path / "out"
    assert sweep(tmp_path, "--vary", "duration=1e-4,2e-3", "--out", str(out), base="edge_beads = 4\n") == 0
    last = capsys.readouterr().err.strip().splitlines()[-1]
    assert last.startswith("hexdem sweep: 1 of 2 runs warned") and "far_wall_not_reached in 1 (duration=1e-4)" in last
    assert "increase 'duration'" in last
    _, rows = read_csv(out / "sweep.csv")
    assert [(row["warnings"], row["far_wall_reached"]) for row in rows] == [
        ("far_wall_not_reached", "False"),
        ("", "True"),
    ]
    (fig,) = drawn
    energy, decay = fig.axes[:2]
    for ax in (energy, decay):
        ringed = [line for line in ax.get_lines() if line.get_markeredgecolor() == "red"]
        assert [list(line.get_xdata()) for line in ringed] == [[1e-4]]
    assert energy.get_yscale() == "log" and "drift" in energy.get_ylabel() and "dimensionless" in energy.get_ylabel()
    low, high = energy.get_ylim()
    assert low < ROUND_OFF and high > MAX_ENERGY_DRIFT


def test_the_table_is_that_of_four_separate_runs(swept, tmp_path):
    """Each row against ``hexdem run`` of the same configuration, run on its own: the same
    numbers to round-off (LAMMPS on one rank is deterministic)."""
    _, rows = read_csv(swept / "sweep.csv")
    for k, row in enumerate(rows):
        config = tmp_path / f"{k}.toml"
        config.write_text(f"v0 = {row['v0']}\n" + SMALL.replace("brass", row["regions.0.material"]))
        assert main(["run", "--config", str(config), "--out", str(tmp_path / str(k))]) == 0
        alone = json.loads((tmp_path / str(k) / "summary.json").read_text())
        for key in ("energy_drift", "energy_lost", "far_wall_reached", "n_samples"):
            assert alone[key] == pytest.approx(
                float(row[key]) if key != "far_wall_reached" else row[key] == "True", rel=1e-12
            )
        _, ours = read_csv(swept / row["run"] / "peaks.csv")
        _, theirs = read_csv(tmp_path / str(k) / "peaks.csv")
        assert ours == theirs


def test_the_runs_show_the_physics_they_must(swept):
    """Elastic Hertz contacts keep the energy. They are scale invariant (x → λx, t → λ^(−1/4) t,
    whatever the materials), so each line's decay exponent does not depend on the striker's
    speed, up to the geometric nonlinearity δ/d: 5e-4 between steel beads at 0.4 m/s, four times
    more between ptfe beads ((m/E*)^(2/5): 0.28 of the mass, 1/115 of E*)."""
    _, rows = read_csv(swept / "sweep.csv")
    by = {(r["regions.0.material"], float(r["v0"])): r for r in rows}
    for _key, row in by.items():
        assert abs(float(row["energy_lost"])) < 1e-4
    for material in ("brass", "ptfe"):
        for line in ("0", "+30", "-30"):
            slow, fast = (float(by[material, v0][f"decay_exponent_{line}"]) for v0 in (0.2, 0.4))
            assert fast == pytest.approx(slow, rel=5e-3)


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
    assert [{k: v for k, v in r.items() if k not in timings} for r in again] == [
        {k: v for k, v in r.items() if k not in timings} for r in rows
    ]


def test_another_plan_in_the_same_directory_is_refused(swept, tmp_path, capsys):
    assert sweep(tmp_path, "--vary", "v0=0.2,0.5", "--out", str(swept), base=SMALL) == 3
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and "another plan" in lines[0]


@pytest.mark.parametrize(
    "options, message",
    [
        (["--vary", "frictoin=0,0.1"], "'frictoin' is not a run-config key"),
        (["--vary", "friction"], "expected KEY=V1,V2,..."),
        (["--vary", "friction=0,,0.1"], "no empty value"),
        (["--vary", "friction="], "no empty value"),
        (["--vary", "friction=0,rough"], "--vary friction must be a number, got 'rough'"),
        (["--vary", "edge_beads=abc,5"], "--vary edge_beads must be an integer, got 'abc'"),
        (["--vary", "initial_state_file=3"], "--vary initial_state_file must be a string, got 3"),
        (["--vary", "dump=yes"], "--vary dump must be true or false, got 'yes'"),
        (["--vary", "regions.0.x_min_d=far"], "--vary regions.0.x_min_d must be a number, got 'far'"),
        (["--vary", "materials.bronze.density_kg_m3=heavy"], "--vary materials.bronze.density_kg_m3 must be a number"),
        (["--vary", "vacancies.0.1=x"], "--vary vacancies.0.1 must be an integer, got 'x'"),
        (
            ["--vary", "friction=0,0.1", "--launcher", "/nonexistent/mpiexec"],
            "cannot start the MPI launcher '/nonexistent/mpiexec': no such executable",
        ),
        (["--vary", "friction=0.1,0.1"], "a value is listed twice"),
        (["--vary", "v0=0.4,0.40"], "two values are the same once read"),
        (["--vary", "friction=0,-0.2"], "run friction=-0.2: friction must be a coefficient >= 0"),
        (["--vary", "v0=0.4", "--vary", "v0=0.2"], "a key is varied twice"),
        (["--vary", "regions.1.material=brass"], "the base configuration has no item 1"),
        (["--vary", "regions.0.material=unobtainium"], "run regions.0.material=unobtainium"),
        (["--vary", "friction=0", "--workers", "0"], "--workers must be a positive integer"),
    ],
)
def test_bad_plans_are_one_line_before_any_run(tmp_path, capsys, options, message):
    """Refused before anything is written: a corrected command may then use the same --out."""
    assert sweep(tmp_path, *options, "--out", str(tmp_path / "out")) == 3
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], lines
    assert not (tmp_path / "out").exists()


def test_nested_keys_change_one_part_of_a_table_or_list():
    base = {"edge_beads": 4, "regions": [{"material": "brass", "x_min_d": 2.0}], "impacts": [{"site": [0, 0]}]}
    runs = plan_sweep(base, [Variation.parse("regions.0.material=ptfe,glass"), Variation.parse("impacts.0.v0=0.3")])
    assert [run.name for run in runs] == [
        "regions.0.material=ptfe,impacts.0.v0=0.3",
        "regions.0.material=glass,impacts.0.v0=0.3",
    ]
    assert [run.config.regions[0]["material"] for run in runs] == ["ptfe", "glass"]
    assert runs[0].config.impacts[0]["v0"] == 0.3 and base["regions"][0]["material"] == "brass"


def test_each_run_reaches_its_rank_through_the_launcher(tmp_path, launcher):
    """--launcher starts each run's ranks (as "srun" would inside an allocation), --ranks-per-run of
    them for a LAMMPS run; the reference engine's runs go the same way, one process each."""
    out = tmp_path / "out"
    assert (
        sweep(
            tmp_path,
            "--vary",
            "engine=lammps,reference",
            "--out",
            str(out),
            "--workers",
            "2",
            "--ranks-per-run",
            "2",
            "--launcher",
            launcher[0],
        )
        == 0
    )
    jobs = {
        job.split(f"{out}/runs/.")[1].split(".part/")[0]: job.split()[:2]  # (each run in .NAME.part)
        for job in launcher[1].read_text().splitlines()
        if f"{out}/runs/" in job
    }
    assert jobs == {"engine=lammps": ["-n", "2"], "engine=reference": ["-n", "1"]}
    _, rows = read_csv(out / "sweep.csv")
    summaries = [json.loads((out / r["run"] / "summary.json").read_text()) for r in rows]
    assert [(s["engine"], s["ranks"]) for s in summaries] == [("lammps", 2), ("reference", 1)]


def test_a_key_idle_in_some_runs_of_a_sweep_is_kept_and_one_idle_in_all_is_refused():
    """A sweep over velocity and striker impacts keeps the base's striker_material (the striker runs
    use it); a sweep that never strikes with a striker refuses it, naming the sweep."""
    base = {"impact": "striker", "striker_material": "brass"}
    runs = plan_sweep(base, [Variation.parse("impact=velocity,striker")])
    assert [run.config.striker_material for run in runs] == ["brass", "brass"]
    with pytest.raises(
        HexdemError, match="^striker_material does nothing in any run of the sweep: no impact is a striker"
    ):
        plan_sweep({"striker_material": "brass"}, [Variation.parse("v0=0.3,0.4")])
