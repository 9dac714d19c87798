"""Sphinx extension: the CLI, configuration and API references, generated from the code at
build time into ``reference/_generated/`` (never edited by hand, never committed).

* ``cli.md``: ``hexdem --help``, the exit statuses and every subcommand's ``--help``, from the
  argparse parser itself;
* ``config.md``: every run-configuration key with its default and type, from :class:`RunConfig`'s
  fields, and its meaning (:data:`~hexdem.model.config_keys.KEY_DESCRIPTIONS`);
* ``api.md`` and ``api_<subpackage>.md``: every module of the package, a page per subpackage and a
  heading per module, through autodoc.

hexdem's docstrings write magnitudes the physicist's way, |v| or |ω_z|, which reStructuredText
would read as substitutions: :func:`escape_bars` escapes every bar outside a grid table's rows
and outside math.
"""

from __future__ import annotations

import dataclasses
import os
import pkgutil
import re
from pathlib import Path

import hexdem
from hexdem.cli.main import COMMANDS, EXIT_CODES, build_parser
from hexdem.model.config import RunConfig
from hexdem.model.config_keys import KEY_DESCRIPTIONS

#: Width of the help texts (argparse reads COLUMNS).
HELP_COLUMNS = "82"
#: A docstring's inline math, whose bars are LaTeX's and stay as written.
MATH_ROLE = re.compile(r"(:math:`[^`]*`)")


def _write(path: Path, text: str) -> None:
    """Write ``text`` only if it changed (an unchanged file keeps Sphinx's cache valid)."""
    if not path.exists() or path.read_text() != text:
        path.write_text(text)


def cli_page() -> str:
    os.environ["COLUMNS"] = HELP_COLUMNS
    lines = [
        "# Command line",
        "",
        "`hexdem` (or `python -m hexdem`) and every subcommand's `--help`, as `hexdem` prints it.",
        "",
        "```text",
        build_parser([]).format_help().rstrip(),
        "```",
        "",
        "## Exit status",
        "",
        "| status | meaning |",
        "|---|---|",
        *(f"| {code} | {meaning} |" for code, meaning in EXIT_CODES.items()),
        "",
    ]
    for name, (_, summary) in COMMANDS.items():
        parser = build_parser([name])
        subcommand = parser._subparsers._group_actions[0].choices[name]
        lines += [
            f"## hexdem {name}",
            "",
            summary[0].upper() + summary[1:] + ".",
            "",
            "```text",
            subcommand.format_help().rstrip(),
            "```",
            "",
        ]
    return "\n".join(lines)


def _default(field: dataclasses.Field) -> str:
    if field.default is not dataclasses.MISSING:
        value = field.default
    elif field.default_factory is not dataclasses.MISSING:
        value = field.default_factory()
    else:
        return "(required)"
    return "(none)" if value is None else f"`{value!r}`"


def config_page() -> str:
    rows = [
        f"| `{f.name}` | {_default(f)} | {str(f.type).replace(' | ', ' or ')} | {KEY_DESCRIPTIONS[f.name]} |"
        for f in dataclasses.fields(RunConfig)
    ]
    return "\n".join(
        [
            "# Run configuration keys",
            "",
            "The keys of a `hexdem run --config FILE.toml` file (and of `hexdem sweep --vary`), with "
            "their defaults and what they mean; a file sets any of them, the rest keep these. "
            "Lengths are in metres; `v0`, `dt` and `duration` in the run's `units`.",
            "",
            "| key | default | type | meaning |",
            "|---|---|---|---|",
            *rows,
            "",
            "```{eval-rst}",
            ".. autoclass:: hexdem.model.config.RunConfig",
            "   :no-members:",
            "   :no-index:",
            "```",
            "",
        ]
    )


def api_pages() -> dict[str, str]:
    """{page name: text}: an index of the subpackages, and one page per subpackage with a heading
    per module (so that the sidebar lists them)."""
    modules = sorted(
        info.name for info in pkgutil.walk_packages(hexdem.__path__, "hexdem.") if not info.name.endswith("__main__")
    )
    packages = sorted({m.split(".")[1] for m in modules})
    pages = {
        "api": "\n".join(
            [
                "# API",
                "",
                "Every module of the package, from its docstrings, one page per subpackage.",
                "",
                "```{toctree}",
                ":maxdepth: 2",
                "",
                *(f"api_{package}" for package in packages),
                "```",
                "",
            ]
        )
    }
    for package in packages:
        lines = [f"# hexdem.{package}", ""]
        for module in (m for m in modules if m.split(".")[1] == package):
            lines += [f"## {module}", "", "```{eval-rst}", f".. automodule:: {module}", "   :members:", "```", ""]
        pages[f"api_{package}"] = "\n".join(lines)
    return pages


def escape_bars(app, what, name, obj, options, lines) -> None:
    """Escape the bars of |v| and the like in a docstring: not in a grid table's row or border,
    nor in a literal block or a math directive (after ``::``, shown as written, where the escape
    would show), nor in a :math: role."""
    literal = None  # indentation of the paragraph that opened the literal block we are in
    for i, line in enumerate(lines):
        indent = len(line) - len(line.lstrip())
        if literal is not None and (not line.strip() or indent > literal):
            continue
        literal = indent if line.rstrip().endswith("::") else None
        if not line.lstrip().startswith(("|", "+")):
            lines[i] = "".join(
                part if part.startswith(":math:") else part.replace("|", "\\|") for part in MATH_ROLE.split(line)
            )


def generate(app) -> None:
    folder = Path(app.srcdir) / "reference" / "_generated"
    folder.mkdir(exist_ok=True)
    for name, text in {"cli": cli_page(), "config": config_page(), **api_pages()}.items():
        _write(folder / f"{name}.md", text)


def setup(app):
    app.connect("builder-inited", generate)
    app.connect("autodoc-process-docstring", escape_bars)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
