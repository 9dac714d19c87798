"""Sphinx configuration of hexdem's documentation (``sphinx-build -W -b html docs OUT``).

The pages are Markdown (MyST). The CLI and configuration references are generated from the
code at build time (``_ext/hexdem_reference.py``), the API reference from the docstrings
(autodoc). Nothing is simulated during a build: the gallery's figures are files that
``gallery/make_gallery.py`` regenerates.
"""

import sys
from importlib.metadata import version as installed_version
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent / "_ext"))

project = "hexdem"
author = "the hexdem developers"
copyright = "2026, the hexdem developers"
release = installed_version("hexdem")
extensions = ["myst_parser", "sphinx.ext.autodoc", "sphinx.ext.napoleon", "hexdem_reference", "hexdem_mathml"]
myst_enable_extensions = ["dollarmath"]
#: Math as MathML written at build time (``_ext/hexdem_mathml.py``): no script, no network.
html_math_renderer = "mathml"
myst_heading_anchors = 3
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
exclude_patterns = ["_build", "gallery/configs"]
autodoc_member_order = "bysource"
autodoc_typehints = "none"
#: The theme of NumPy's, SciPy's and MDAnalysis's sites, which hexdem's readers know.
html_theme = "pydata_sphinx_theme"
html_title = "hexdem"
#: The page's own headings below the section's navigation, in the one sidebar: without a second
#: sidebar the article is wide enough for the 82 columns of the code blocks and CLI help at 1280 px
#: (an API page lists its modules there).
html_theme_options = {
    "logo": {"text": "hexdem"},
    "navbar_align": "left",
    "show_toc_level": 2,
    "navigation_with_keys": False,
    "secondary_sidebar_items": [],
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
}
html_sidebars = {"**": ["sidebar-nav-bs", "page-toc"]}
html_static_path = ["_static"]
html_css_files = ["hexdem.css"]
suppress_warnings = ["myst.header", "myst.xref_missing"]
#: Module headings in that table of contents, not every function (their names would be cut off).
toc_object_entries = False
