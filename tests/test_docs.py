"""The documentation site builds with warnings as errors, its generated references cover the
code, its formulas are typeset, its gallery covers every packing and impact kind, and the README
is a front page whose set-up commands are those CI runs."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

from hexdem.cli.main import COMMANDS
from hexdem.model.config import SHAPES, RunConfig
from hexdem.model.config_keys import KEY_DESCRIPTIONS
from hexdem.model.model_builder import build_model

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """The HTML site, built from scratch (-E) with every warning an error (-W)."""
    out = tmp_path_factory.mktemp("docs") / "html"
    done = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-E", "-q", "-b", "html",
                           str(DOCS), str(out)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return out


def test_the_cli_reference_holds_every_subcommands_help(built):
    page = (built / "reference" / "_generated" / "cli.html").read_text()
    for name in COMMANDS:
        assert f"hexdem {name}" in page
    assert "--vary KEY=V1,V2,..." in page and "--steps-per-contact" in page


def test_the_config_reference_lists_every_key(built):
    page = (built / "reference" / "_generated" / "config.html").read_text()
    import dataclasses

    missing = [f.name for f in dataclasses.fields(RunConfig) if f"<code class=\"docutils literal notranslate\"><span class=\"pre\">{f.name}</span>" not in page]
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
    models = {name: build_model(config) for name, config in configs.items()}
    kinds = {"velocity": any(not m.strikers for m in models.values()),
             "striker": any(len(m.strikers) == 1 for m in models.values()),
             "several impacts": any(len(m.impacts) > 1 and not m.strikers for m in models.values()),
             "a flat striker": any(len(m.strikers) > 1 for m in models.values()),
             "an interior impact": any(config.precompression_n > 0 for config in configs.values())}
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
    """'eq. (4)', as the paper numbers them, never the LaTeX source's labels ('eq. (v30)', '(TCA_decay)')."""
    label = re.compile(r"[Ee]qs?\. \([A-Za-z_]\w*\)|\((?:v30|v0|veq0|hyperg|TCA_strain|TCA_decay|BCA_decay)\)")
    pages = [path for path in built.rglob("*.html") if "_static" not in path.parts]
    raw = [(path.name, hit) for path in pages for hit in label.findall(path.read_text())]
    assert not raw, raw[:5]


#: Characters of a code line that the page shows without clipping (alabaster at 1100 px).
CODE_COLUMNS = 84


def test_no_code_line_is_wider_than_the_page(built):
    """Every line of every code block, the generated references' included, fits the page, and
    shows a docstring's |v| as written (no escape)."""
    import html

    lines = [(path.name, line) for path in built.rglob("*.html") if "_static" not in path.parts
             for block in re.findall(r"<pre>(.*?)</pre>", path.read_text(), flags=re.DOTALL)
             for line in html.unescape(re.sub(r"<[^>]+>", "", block)).splitlines()]
    wide = [(name, line) for name, line in lines if len(line) > CODE_COLUMNS]
    assert not wide, wide[:5]
    assert not [line for _, line in lines if "\\|" in line]


def test_the_pages_count_the_slow_tests():
    """The number of `slow` tests the pages quote is the number pytest collects with ``-m slow``."""
    quoted = [int(count) for page in ("development.md", "getting-started.md")
              for count in re.findall(r"(\d+) tests (?:are )?marked\s+`?slow", (DOCS / page).read_text())]
    done = subprocess.run([sys.executable, "-m", "pytest", "--collect-only", "-q", "-m", "slow", "-p", "no:cacheprovider",
                           str(ROOT / "tests")], cwd=ROOT, capture_output=True, text=True, timeout=300)
    collected = re.search(r"(\d+)/\d+ tests collected", done.stdout)
    assert collected, done.stdout[-2000:]
    assert len(quoted) == 2 and set(quoted) == {int(collected.group(1))}


#: Modules and pages whose formulas are still plain text: their files were being rewritten when
#: the rest became math (issue 35). Each leaves the set as its formulas are converted.
PLAIN_TEXT_FORMULAS = {"hexdem.analysis.energy", "hexdem.analysis.tracker_kernel",
                       "hexdem.engines.lammps.deck", "hexdem.engines.reference.engine",
                       "hexdem.engines.reference.kernel", "hexdem.model.timescale",
                       "hexdem.paper.crossover", "hexdem.paper.friction_study", "validation/crossover.html"}


def test_formulas_are_typeset_not_raw_latex(built):
    """No ``^{``, ``^(`` or ``_{`` in a page's text outside code and math: a formula is math
    (``$...$`` on a page, ``:math:`` in a docstring), which the page shows typeset (MathML).
    An API page is read module by module."""
    import html

    raw = {}
    for path in built.rglob("*.html"):
        if "_static" in path.parts:
            continue
        page = re.sub(r"<(pre|code|math)\b.*?</\1>", "", path.read_text(), flags=re.DOTALL)
        for part in re.split(r'(?=<section id="module-)', page):
            module = re.match(r'<section id="module-([\w.]+)"', part)
            text = html.unescape(re.sub(r"<[^>]+>", "", part))
            hits = re.findall(r".{0,30}(?:\^[{(]|_\{).{0,30}", text)
            if hits:
                raw[module.group(1) if module else path.relative_to(built).as_posix()] = hits
    assert set(raw) <= PLAIN_TEXT_FORMULAS, {name: raw[name] for name in set(raw) - PLAIN_TEXT_FORMULAS}
    assert PLAIN_TEXT_FORMULAS <= set(raw), f"math now, leave the set: {PLAIN_TEXT_FORMULAS - set(raw)}"


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
