"""Every benchmark runs: ``benchmarks/bench_*.py --quick`` exits 0 and prints its table under a machine line.

The quick modes take the full modes' code paths on small packings and few steps (seconds
each), so that an API change that breaks a benchmark is caught here rather than when
someone next measures. The paper benchmark resumes the session's ``hexdem paper --quick``
(tests/test_paper.py) rather than running the pipeline a second time.
"""

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BENCHMARKS = ROOT / "benchmarks"
sys.path.insert(0, str(BENCHMARKS))
from baseline import BEFORE, KEPT_ENV  # noqa: E402  (the revision the benchmarks compare with)

#: Words each benchmark's printed table must contain (headers, row names, the target line).
EXPECTED = {
    "bench_analysis.py": (
        "beads",
        "part",
        "before",
        "NumPy",
        "compiled",
        "before / compiled",
        "samples",
        "tracker",
        "audit",
        "gathering",
        "result files",
    ),
    "bench_accuracy.py": (
        "case",
        "engine",
        "steps/τ",
        "peak error",
        "arrival [µs]",
        "energy drift",
        "order",
        "wall [s]",
        "lammps",
        "reference",
        "target at 140 steps per contact",
    ),
    "bench_design.py": (
        "design:",
        "simulations",
        "predicted 90 % width",
        "measured median 90 % width",
        "predicted ratio best",
        "within 30 %",
    ),
    "bench_results.py": (
        "beads",
        "never moved",
        "run [s]",
        "results, before [s]",
        "results, now [s]",
        "before / now",
        "target [s]",
        "target: the result files",
    ),
    "bench_run.py": (
        "runner",
        "wall [s]",
        "loop [s]",
        "wall / bare loop",
        "hexdem run (CLI, subprocess)",
        "run_experiment (in-process)",
        "bare lmp -in in.nooutput",
        "import floor",
        "target end to end",
        "in-run analysis (now)",
        "where the CLI's time goes",
    ),
    "bench_reference.py": (
        "lattice",
        "beads",
        "engine",
        "steps",
        "M (bead|atom)-steps/s",
        "reference (RK4, 1 thread)",
        "LAMMPS in hexdem, 1 rank",
        "LAMMPS bare, 2 ranks",
        "target >= 20",
    ),
    "bench_ensemble.py": (
        "runner",
        "LAMMPS [s]",
        "hexdem, 1 rank",
        "hexdem, 2 ranks",
        "bare lmp, 2 ranks",
        "version",
        "compact",
        "settle",
        "impacts",
        "target <= 60 s",
    ),
    "bench_scale.py": (
        "beads",
        "ranks",
        "model [s]",
        "data file [s]",
        "bare loop [s]",
        "hexdem loop [s]",
        "analysis",
        "run [s]",
        "results [s]",
        "end-to-end [s]",
        "largest process [MB]",
        "peak RSS per rank [MB]",
        "collectives",
        "rebuilds",
        "audited",
        "part by part inside the run",
        "gathering",
        "where hexdem's loop exceeds",
        "target collectives",
        "target per-rank memory",
        "target largest process",
        "target results",
    ),
    "bench_study.py": (
        "executor",
        "runs [s]",
        "start-up and end [s]",
        "a run, in-process",
        "overhead per run [s]",
        "process pool",
        "Parsl (HighThroughputExecutor, local)",
        "Parsl's overhead per run over the pool's",
        "target <= 0.2 s or 5% of a run",
    ),
    "bench_calibration.py": (
        "case tiny",
        "truth",
        "v0 true",
        "v0 90 % interval",
        "v0 rank",
        "simulations",
        "fit p",
        "wall s",
        "coverage 50 %",
        "coverage 90 %",
        "binomial band (95 %)",
        "rank histogram",
        "uniformity p",
    ),
    "bench_paper.py": (
        "hexdem paper --quick",
        "part",
        "wall [s]",
        "scaling",
        "disorder-sigma6tol",
        "sum of parts",
        "this invocation",
        "target <= 120 s",
        "140 steps",
    ),
}
#: What the benchmarks that compare with the code before the speed work print of it, where this
#: clone holds that revision (the paper's is checked on a resumed run, today's only).
BEFORE_WORDS = {"bench_run.py": ("(before)", "before / now"), "bench_ensemble.py": ("(before)", "before / now")}


def has_revision(revision: str) -> bool:
    return (
        subprocess.run(
            ["git", "-C", str(ROOT), "cat-file", "-e", f"{revision}^{{commit}}"], capture_output=True, check=False
        ).returncode
        == 0
    )


#: The marks of the quick runs of a minute or more: the paper's reads the session's paper run, on
#: the worker that runs it (conftest.py).
SLOW = {
    "bench_paper.py": (pytest.mark.slow, pytest.mark.xdist_group("paper_quick")),
    "bench_scale.py": (pytest.mark.slow,),
}


def test_every_benchmark_is_checked():
    assert sorted(path.name for path in BENCHMARKS.glob("bench_*.py")) == sorted(EXPECTED)


@pytest.fixture(scope="module")
def baselines(tmp_path_factory):
    """The environment of the quick runs: the revisions they compare with unpacked once, into one
    folder that they share (``baseline.KEPT_ENV``)."""
    return {**os.environ, KEPT_ENV: str(tmp_path_factory.mktemp("baselines"))}


@pytest.mark.parametrize("script", [pytest.param(script, marks=SLOW.get(script, ())) for script in sorted(EXPECTED)])
def test_quick_benchmark_runs(script, request, baselines):
    # the paper benchmark reports on the session's quick paper run instead of a second one
    extra = ["--out", str(request.getfixturevalue("paper_quick"))] if script == "bench_paper.py" else []
    done = subprocess.run(
        [sys.executable, str(BENCHMARKS / script), "--quick", *extra],
        cwd=ROOT,
        check=False,
        capture_output=True,
        text=True,
        timeout=180,
        env=baselines,
    )
    assert done.returncode == 0, f"{script} --quick failed:\n{done.stdout}\n{done.stderr[-3000:]}"
    lines = done.stdout.splitlines()
    assert lines and lines[0].startswith("machine: ") and "cores" in lines[0], done.stdout
    expected = EXPECTED[script] + (BEFORE_WORDS.get(script, ()) if has_revision(BEFORE) else ())
    missing = [word for word in expected if word not in done.stdout]
    assert not missing, f"{script} --quick printed no {missing}:\n{done.stdout}"
