"""The documentation site builds with warnings as errors, its generated references cover the
code, its formulas are typeset, its gallery covers every packing and impact kind, and the README
is a front page whose set-up commands are those CI runs."""

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from hexdem.cli.main import COMMANDS
from hexdem.model.config import SHAPES, RunConfig
from hexdem.model.config_keys import KEY_DESCRIPTIONS
from hexdem.model.model_builder import build_model
from hexdem.model.packing_builders import PREPARED_SHAPES

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """The HTML site, built from scratch (-E) with every warning an error (-W)."""
    out = tmp_path_factory.mktemp("docs") / "html"
    done = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-E", "-q", "-b", "html", str(DOCS), str(out)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    return out


def test_the_cli_reference_holds_every_subcommands_help(built):
    page = (built / "reference" / "_generated" / "cli.html").read_text()
    for name in COMMANDS:
        assert f"hexdem {name}" in page
    assert "--vary KEY=V1,V2,..." in page and "--steps-per-contact" in page


def test_the_site_wears_the_theme_of_numpy_scipy_and_mdanalysis(built):
    """pydata-sphinx-theme, with hexdem's stylesheet (math at the text's size, titles that wrap on a
    phone; checked in Chromium at 1280 and 390 px), and the CLI reference's exit statuses."""
    page = (built / "index.html").read_text()
    assert "pydata-sphinx-theme.css" in page and "_static/hexdem.css" in page
    assert (built / "_static" / "hexdem.css").read_text() == (DOCS / "_static" / "hexdem.css").read_text()
    cli = (built / "reference" / "_generated" / "cli.html").read_text()
    assert "Exit status" in cli and "a simulation that started and failed" in cli


def test_the_config_reference_lists_every_key(built):
    page = (built / "reference" / "_generated" / "config.html").read_text()
    import dataclasses

    missing = [
        f.name
        for f in dataclasses.fields(RunConfig)
        if f'<code class="docutils literal notranslate"><span class="pre">{f.name}</span>' not in page
    ]
    assert not missing
    assert set(KEY_DESCRIPTIONS) == {f.name for f in dataclasses.fields(RunConfig)}, "every key says what it means"
    rows = re.findall(r"<tr class=\"row-(?:odd|even)\">(.*?)</tr>", page.split("</thead>")[1], flags=re.DOTALL)
    assert len(rows) == len(dataclasses.fields(RunConfig))
    assert all(row.count("<td>") == 4 for row in rows), "an optional type's bar no longer splits its cell"
    assert "int or None" in page


def test_the_api_reference_documents_the_modules_a_page_per_subpackage(built):
    """Each subpackage on its own page (the whole API was one 1.1 MB page), each module a heading."""
    folder = built / "reference" / "_generated"
    for name in ("hexdem.model.contact_law", "hexdem.experiments.sweep", "hexdem.paper.friction_study"):
        page = (folder / f"api_{name.split('.')[1]}.html").read_text()
        assert f'id="module-{name}"' in page and f"<h2>{name}" in page
    assert max(path.stat().st_size for path in folder.glob("api_*.html")) < 600e3


def test_the_gallery_shows_every_shape_and_impact_kind():
    configs = {path.stem: RunConfig.from_toml(path) for path in sorted((DOCS / "gallery" / "configs").glob("*.toml"))}
    assert {config.shape for config in configs.values()} == set(SHAPES)
    models = {name: build_model(config) for name, config in configs.items() if config.shape not in PREPARED_SHAPES}
    kinds = {
        "velocity": any(not m.strikers for m in models.values()),
        "striker": any(len(m.strikers) == 1 for m in models.values()),
        "several impacts": any(len(m.impacts) > 1 and not m.strikers for m in models.values()),
        "a flat striker": any(len(m.strikers) > 1 for m in models.values()),
        "an interior impact": any(config.precompression_n > 0 for config in configs.values()),
    }
    assert all(kinds.values()), kinds
    page = (DOCS / "gallery" / "index.md").read_text()
    for name in configs:
        assert f"configs/{name}.toml" in page and (DOCS / "gallery" / "images" / f"{name}.png").exists()


def test_the_readme_is_a_front_page_with_the_commands_ci_runs():
    readme = (ROOT / "README.md").read_text()
    assert len(readme.splitlines()) <= 200
    ci = (ROOT / ".ci" / "run").read_text().splitlines()[-1]
    assert ci in readme, "the README's test command is the one .ci/run calls"
    assert "python3 -m venv .venv && .venv/bin/pip install -q . && .venv/bin/hexdem run" in readme
    for link in re.findall(r"\]\((docs/[^)#]+)", readme):
        assert (ROOT / link).exists(), link
    assert re.search(r"!\[[^]]*\]\(docs/gallery/images/\w+\.png\)", readme), "one picture"


def test_equations_are_cited_by_the_papers_numbers(built):
    """'eq. (4)', as the paper numbers them, never the LaTeX source's labels ('eq. (v30)', '(TCA_decay)',
    'eq. TCA_decay')."""
    names = "v30|v0|veq0|hyperg|TCA_strain|TCA_decay|BCA_decay"
    label = re.compile(rf"[Ee]qs?\. \([A-Za-z_]\w*\)|\((?:{names})\)|[Ee]qs?\. (?:{names})\b")
    pages = [path for path in built.rglob("*.html") if "_static" not in path.parts]
    raw = [(path.name, hit) for path in pages for hit in label.findall(path.read_text())]
    assert not raw, raw[:5]


#: Characters of a code line that the page shows without clipping: at a 1280 px window an
#: 84-character line lost its last letter; 82 keeps a margin.
CODE_COLUMNS = 82


def test_no_code_line_is_wider_than_the_page(built):
    """Every line of every code block, the generated references' included, fits the page, and
    shows a docstring's |v| as written (no escape)."""
    import html

    lines = [
        (path.name, line)
        for path in built.rglob("*.html")
        if "_static" not in path.parts
        for block in re.findall(r"<pre>(.*?)</pre>", path.read_text(), flags=re.DOTALL)
        for line in html.unescape(re.sub(r"<[^>]+>", "", block)).splitlines()
    ]
    wide = [(name, line) for name, line in lines if len(line) > CODE_COLUMNS]
    assert not wide, wide[:5]
    assert not [line for _, line in lines if "\\|" in line]


def slow_tests(request) -> int:
    """How many tests pytest collects with ``-m slow``: counted in this session where it collected
    the whole suite, unselected (as CI runs it), else by a collection of its own."""
    option, items = request.config.option, request.session.items
    whole = (
        not option.keyword
        and not option.markexpr
        and not option.deselect
        and not getattr(option, "lf", False)
        and {item.path.name for item in items} >= {path.name for path in (ROOT / "tests").glob("test_*.py")}
    )
    if whole:
        return sum(item.get_closest_marker("slow") is not None for item in items)
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "pytest",
            "--collect-only",
            "-q",
            "-m",
            "slow",
            "-p",
            "no:cacheprovider",
            str(ROOT / "tests"),
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
    )
    collected = re.search(r"(\d+)/\d+ tests collected", done.stdout)
    assert collected, done.stdout[-2000:]
    return int(collected.group(1))


def test_the_pages_count_the_slow_tests(request):
    """The number of `slow` tests the pages quote is the number pytest collects with ``-m slow``."""
    quoted = [
        int(count)
        for page in ("development.md", "getting-started.md")
        for count in re.findall(r"(\d+) tests (?:are )?marked\s+`?slow", (DOCS / page).read_text())
    ]
    assert len(quoted) == 2 and set(quoted) == {slow_tests(request)}


def test_formulas_are_typeset_not_raw_latex(built):
    """No ``^{``, ``^(`` or ``_{``, nor a bare power such as ``r^a``, ``R^−p`` or ``m^1.5``, in a
    page's text outside code and math: a formula is math (``$...$`` on a page, ``:math:`` in a
    docstring), which the page shows typeset (MathML). Code is ``<pre>``, ``<code>`` and the
    signatures' ``<span class="pre">`` (a value such as ``'o^v<>sD'``). An API page is read
    module by module."""
    import html

    raw = {}
    for path in built.rglob("*.html"):
        if "_static" in path.parts:
            continue
        page = re.sub(
            r"<(pre|code|math)\b.*?</\1>|<span class=\"pre\">[^<]*</span>", "", path.read_text(), flags=re.DOTALL
        )
        for part in re.split(r'(?=<section id="module-)', page):
            module = re.match(r'<section id="module-([\w.]+)"', part)
            text = html.unescape(re.sub(r"<[^>]+>", "", part))
            hits = re.findall(r".{0,30}(?:\^[{(]|_\{|\w\^[−-]?\w).{0,30}", text)
            if hits:
                raw[module.group(1) if module else path.relative_to(built).as_posix()] = hits
    assert not raw, raw


def test_docstrings_with_backslashes_are_raw_strings():
    r"""A docstring's LaTeX keeps its backslashes only in a raw string: in a plain one ``\nu``
    is a newline, ``\frac`` a form feed and ``\sqrt`` an invalid escape."""
    import ast

    plain = []
    for path in sorted((ROOT / "hexdem").rglob("*.py")):
        source = path.read_text()
        for node in ast.walk(ast.parse(source)):
            if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef)) and ast.get_docstring(node, clean=False):
                text = ast.get_source_segment(source, node.body[0].value)
                if "\\" in text and not text.startswith("r"):
                    plain.append(f"{path.relative_to(ROOT)}:{node.body[0].lineno}")
    assert not plain, plain


def _sci(value: float, digits: int = 2) -> str:
    """A number as the pages write it: ``digits`` significant digits, 1.6e-4."""
    mantissa, exponent = f"{value:.{digits - 1}e}".split("e")
    return f"{mantissa}e{int(exponent)}"


def _quoted_numbers() -> list[tuple[str, str, tuple]]:
    """(page, pattern, the numbers its groups must read, as the source gives them): every number
    a page quotes from a constant of the code, or from the theory the code computes, set in one place."""
    sys.path.insert(0, str(ROOT / "benchmarks"))
    import bench_accuracy
    import bench_ensemble
    import bench_paper
    import bench_reference
    import bench_run
    import bench_scale

    from hexdem.experiments import compare
    from hexdem.model import chain, config, placed, run_settings, square_crystals
    from hexdem.model.dissipation import damping_coefficient
    from hexdem.theory.phonons import Lattice2D, cone_slope, frequencies, sound_speeds
    from hexdem.waves.conical import ConicalSettings

    force = ConicalSettings().precompression_n
    lattice_config = config.RunConfig(precompression_n=force)
    lattice = Lattice2D.of(lattice_config)
    omega_m = frequencies(lattice, lattice.high_symmetry_points()["M"]) / (2 * np.pi * 1e3)
    n = config.STEPS_PER_CONTACT
    elastic = [(steps, [compare.MARGIN * e for e in compare.expected_error(steps)]) for steps in (n, 2 * n)]
    damped = [compare.MARGIN * e for e in compare.expected_error(n, damping_coefficient(0.95))]
    return [
        ("docs/validation/convergence.md", r"`steps_per_contact` = (\d+)", (f"{n}",)),
        (
            "docs/validation/convergence.md",
            r"samples every τ/(\d+) whatever the step \(`dump_every` default: "
            r"steps_per_contact / (\d+); a step count that is not a multiple of (\d+)",
            (f"{run_settings.SAMPLES_PER_CONTACT}",) * 3,
        ),
        (
            "docs/validation/convergence.md",
            r"peak speeds within ([\d.e-]+) relative and arrival times within ([\d.]+) µs",
            (_sci(bench_accuracy.PEAK_TARGET, 1), f"{bench_accuracy.ARRIVAL_TARGET_S * 1e6:g}"),
        ),
        ("docs/guide/configuration.md", r"\bsteps_per_contact = (\d+)", (f"{n}",)),
        ("docs/guide/paper.md", r"\[--steps-per-contact (\d+)\]", (f"{n}",)),
        (
            "docs/guide/impacts.md",
            r"fewer than (\d+) samples or fewer than (\d+) per contact time",
            (f"{run_settings.MIN_SAMPLES}", f"{run_settings.MIN_SAMPLES_PER_CONTACT}"),
        ),
        (
            "docs/validation/engines.md",
            r"rounded up to ([\d.]+)/N²\), and in arrival time",
            (f"{compare.PEAK_ERROR_N2:g}",),
        ),
        (
            "docs/validation/engines.md",
            r"at most \(([\d.]+) τ \+ ([\d.]+) t\)/N²",
            (f"{compare.ARRIVAL_ERROR_N2:g}", f"{compare.ARRIVAL_GROWTH_N2:g}"),
        ),
        (
            "docs/validation/engines.md",
            r"rounded up to ([\d.]+) and ([\d.]+)\), halving",
            (f"{compare.PEAK_ERROR_ALPHA_N:g}", f"{compare.ARRIVAL_ERROR_ALPHA_N:g}"),
        ),
        ("docs/validation/engines.md", r"tolerances are (\d+) times that expected error", (f"{compare.MARGIN:g}",)),
        *[
            (
                "docs/validation/engines.md",
                rf"\| elastic, N = {steps}[^|]*\| ([\d.e-]+) \| ([\d.e-]+) τ \+ ([\d.e-]+) t",
                tuple(map(_sci, tolerance)),
            )
            for steps, tolerance in elastic
        ],
        (
            "docs/validation/engines.md",
            rf"\| e = 0.95, N = {n} \| ([\d.e-]+) \| ([\d.e-]+) τ \+ ([\d.e-]+) t",
            tuple(map(_sci, damped)),
        ),
        (
            "docs/validation/engines.md",
            rf"the peak tolerance takes ([\d.]+)/N² \(`PLACED_PEAK_ERROR_N2`\): ([\d.e-]+) at N = {n}",
            (f"{compare.PLACED_PEAK_ERROR_N2:.1f}", _sci(compare.MARGIN * compare.PLACED_PEAK_ERROR_N2 / n**2)),
        ),
        (
            "README.md",
            r"at (\d+) N per contact, \S+ = ([\d.]+) Hz and the cone's slope .*? = ([\d.]+) m/s",
            (f"{force:g}", f"{lattice.dirac_frequency() / (2 * np.pi):.1f}", f"{cone_slope(lattice):.2f}"),
        ),
        (
            "docs/guide/dirac-point.md",
            r"\| at (\d+) N, steel, d = ([\d.]+) mm \|",
            (f"{force:g}", f"{lattice_config.diameter_m * 1e3:.2f}"),
        ),
        (
            "docs/guide/dirac-point.md",
            r"\| \S+ = ([\d.]+) m/s, \S+ = ([\d.]+) m/s \|",
            tuple(f"{c:.1f}" for c in sound_speeds(lattice)),
        ),
        ("docs/guide/dirac-point.md", r"\| \S+ = ([\d.]+) Hz \|", (f"{lattice.dirac_frequency() / (2 * np.pi):.1f}",)),
        ("docs/guide/dirac-point.md", r"\| \S+ = ([\d.]+) m/s \|", (f"{cone_slope(lattice):.2f}",)),
        ("docs/guide/dirac-point.md", r"\| ([\d.]+) and ([\d.]+) kHz \|", tuple(f"{f:.2f}" for f in sorted(omega_m))),
        (
            "docs/validation/benchmarks.md",
            r"end to end ≤ floor \+ ([\d.]+) × the LAMMPS loop \+ ([\d.]+) s; the in-run "
            r"analysis ≤ ([\d.]+) × the loop",
            (f"{bench_run.TARGET_FACTOR:g}", f"{bench_run.TARGET_OFFSET_S:g}", f"{bench_run.ANALYSIS_SHARE_TARGET:g}"),
        ),
        (
            "docs/validation/benchmarks.md",
            r"at ([\d,]+) beads on (\d+) ranks the largest process ≤ (\d+) MB;.*?the\s+tables equal to "
            r"round-off, ([\de-]+) relative",
            (
                f"{bench_scale.MEMORY_TARGET_RUN[0]:,}",
                f"{bench_scale.MEMORY_TARGET_RUN[1]}",
                f"{bench_scale.MEMORY_TARGET / 1e6:g}",
                _sci(bench_scale.RESULTS_RTOL, 1),
            ),
        ),
        (
            "docs/validation/benchmarks.md",
            r"target ≥ (\d+) M for (\d+) beads",
            (f"{bench_reference.TARGET_M_BEAD_STEPS:g}", f"{bench_reference.TARGET_BEADS}"),
        ),
        (
            "docs/validation/benchmarks.md",
            r"\(targets: ≤ (\d+) s, ≥ ([\d.]+) × faster than before\)",
            (f"{bench_ensemble.ENSEMBLE_TARGET_S:g}", f"{bench_ensemble.ENSEMBLE_SPEED_UP_TARGET:g}"),
        ),
        (
            "docs/validation/benchmarks.md",
            r"targets: ≤ (\d+) min for the parts .*? `--quick` ≤ (\d+) min; ≥ ([\d.]+) × faster",
            (
                f"{bench_paper.TARGETS_S[False] / 60:g}",
                f"{bench_paper.TARGETS_S[True] / 60:g}",
                f"{bench_paper.SPEED_UP_TARGET:g}",
            ),
        ),
        (
            "docs/guide/packings.md",
            r"by more than ([\d.e-]+) of the smaller diameter are refused.*?that "
            r"tolerance \((\d+) nm for the paper's beads\)",
            (
                _sci(placed.MAX_REST_OVERLAP, 1).replace(".0e", "e"),
                f"{placed.MAX_REST_OVERLAP * config.RunConfig().diameter_m * 1e9:.0f}",
            ),
        ),
        (
            "docs/guide/packings.md",
            r"a chain at least (\d+) beads, a square or centered-square crystal at least "
            r"(\d+) rows and (\d+) columns",
            (f"{chain.MIN_CHAIN_BEADS}", *(f"{square_crystals.MIN_GRID}",) * 2),
        ),
        (
            "docs/guide/packings.md",
            r"spread over more than (\d+) times all of them laid end to end.*? not within "
            r"a factor (\d+) of `diameter_m`",
            (f"{placed.MAX_SPAN_FACTOR:g}", f"{placed.MAX_DIAMETER_RATIO:g}"),
        ),
    ]


def test_the_pages_quote_the_numbers_of_their_source():
    """A number a page quotes from the code (the time step, the sampling, the engines' tolerances,
    the benchmarks' targets) reads what the code sets: change either, and this fails."""
    wrong = []
    for page, pattern, expected in _quoted_numbers():
        found = re.search(pattern, " ".join((ROOT / page).read_text().split()))
        if found is None or found.groups() != expected:
            wrong.append((page, pattern[:40], found.groups() if found else "not quoted", expected))
    assert not wrong, wrong


def test_the_crossover_page_shows_its_runs_numbers():
    """The crossover page's tables are those the report draws from the run's
    ``disorder_crossover.json``, kept beside the page; its σ lists and δ(V) are the code's."""
    from hexdem.disorder.preparation import TOLERANCE_M
    from hexdem.paper import settings
    from hexdem.paper.crossover import (
        FIT_TABLE_HEADER,
        OVERLAP_TABLE_HEADER,
        fit_table,
        impact_overlap_m,
        overlap_table,
    )

    page = (DOCS / "validation" / "crossover.md").read_text()
    run = json.loads((DOCS / "validation" / "data" / "disorder_crossover.json").read_text())
    rows = [FIT_TABLE_HEADER, *fit_table(run["fits"]), OVERLAP_TABLE_HEADER, *overlap_table(run["overlap_test"])]
    missing = [row for row in rows if "| " + " | ".join(row) + " |" not in page]
    assert not missing, missing
    assert run["sigma_per_tol"] == sorted({*settings.SIGMA_PER_TOL, *settings.CROSSOVER_SIGMA_PER_TOL} - {0.0})
    text = " ".join(page.split())
    sweep = re.search(r"σ/tol ∈ \{([^}]*)\} \(quick: \{([^}]*)\}\)", text)
    assert sweep and [tuple(float(s) for s in group.split(", ")) for group in sweep.groups()] == [
        tuple(s for s in chosen if s not in settings.SIGMA_PER_TOL)
        for chosen in (settings.CROSSOVER_SIGMA_PER_TOL, settings.QUICK_CROSSOVER_SIGMA_PER_TOL)
    ]
    overlaps = re.search(r"is ([\d.]+), ([\d.]+) and ([\d.]+) tol at ([\d.]+), ([\d.]+) and ([\d.]+) m/s", text)
    speeds = settings.CROSSOVER_VELOCITIES_M_S
    assert overlaps and overlaps.groups() == (
        *(f"{impact_overlap_m(v) / TOLERANCE_M:.2f}" for v in speeds),
        *(f"{v:.2f}" for v in speeds),
    )


def test_the_api_reference_renders_numpydoc_sections(built):
    """The Python API's functions and the classes they return show their numpydoc sections as
    sections (Napoleon), not as raw underlined headings."""
    page = (built / "reference" / "_generated" / "api_api.html").read_text()
    for section in ("Parameters", "Returns", "Raises"):
        assert re.search(rf"<dt[^>]*>{section}<span class=\"colon\">", page), section
    assert "----------" not in page
    for attribute in ("peak_speed", "arrival_time", "energy_drift", "far_wall_reached", "bead_id"):
        assert f'id="hexdem.api.ImpactResult.{attribute}"' in page or f'id="hexdem.api.LineResult.{attribute}"' in page
