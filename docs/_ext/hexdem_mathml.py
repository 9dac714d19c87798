"""Sphinx extension: the pages' math (``$...$`` in Markdown, :math:`...` in docstrings) as
MathML, converted at build time by docutils' LaTeX-to-MathML converter.

Browsers typeset MathML themselves, so a page shows its formulas without a script or a network
(Sphinx's default, MathJax, comes from a CDN). Unicode letters and signs may stand in the LaTeX
(δ, ∝, −), as docutils' own MathML output allows. LaTeX the converter cannot read is a build
warning, hence an error under ``-W``.
"""

from __future__ import annotations

from docutils import nodes
from docutils.utils.math import MathError, latex2mathml, unichar2tex
from sphinx.util import logging

logger = logging.getLogger(__name__)
#: A slash as TeX sets it, an ordinary symbol (δ^{3/2} shows 3/2), not an operator with space
#: either side (3 / 2) as the converter writes it.
SLASH = '<mo stretchy="false">/</mo>', '<mo stretchy="false" lspace="0" rspace="0">/</mo>'


def mathml(translator, node, block: bool) -> str:
    tex = node.astext()
    try:
        return latex2mathml.tex2mathml(tex.translate(unichar2tex.uni2tex_table), as_block=block).replace(*SLASH)
    except MathError as err:
        logger.warning("math %r cannot be converted to MathML: %s", tex, err, location=node)
        return translator.encode(tex)


def visit_math(translator, node) -> None:
    translator.body.append(mathml(translator, node, block=False))
    raise nodes.SkipNode


def visit_displaymath(translator, node) -> None:
    translator.body += [
        translator.starttag(node, "div", CLASS="math"),
        mathml(translator, node, block=True),
        "</div>\n",
    ]
    raise nodes.SkipNode


def setup(app):
    app.add_html_math_renderer("mathml", (visit_math, None), (visit_displaymath, None))
    return {"parallel_read_safe": True, "parallel_write_safe": True}
