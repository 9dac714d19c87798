"""How large a figure's text is where the report shows it: a figure wider than the page's
column (:data:`~hexdem.common.html_page.COLUMN_PX`) is shrunk to it, and its text with it."""

from __future__ import annotations

from matplotlib.text import Text

from hexdem.analysis import plotting as plots
from hexdem.common.html_page import COLUMN_PX


def saved_figure(monkeypatch, draw):
    """The figure that ``draw()`` hands to :func:`hexdem.analysis.plotting.save` (nothing written)."""
    saved = []
    monkeypatch.setattr(plots, "save", lambda fig, path: saved.append(fig))
    draw()
    assert len(saved) == 1
    return saved[0]


def smallest_text_px(fig) -> float:
    """The height [px] of the figure's smallest text as the report's column shows the PNG."""
    fig.canvas.draw()
    shown = min(1.0, COLUMN_PX / (fig.get_figwidth() * plots.DPI))
    sizes = [text.get_fontsize() for text in fig.findobj(Text) if text.get_visible() and text.get_text().strip()]
    return min(sizes) / 72 * plots.DPI * shown
