"""A self-contained HTML page of headings, paragraphs, tables and figures: what a study
leaves for a person to read in a browser, its PNG figures embedded so the one file travels.

Blocks are tuples: ("h1" | "h2" | "p", text), ("table", header, rows of strings),
("figure", PNG file name in ``out``, caption).
"""

from __future__ import annotations

import base64
import html
from pathlib import Path

#: Width of the page's column [px] (70 em of 16 px): a figure wider than this is shown this wide.
COLUMN_PX = 1120


def render_html(blocks: list, out: Path, title: str) -> str:
    """The page of ``blocks`` (module docstring) titled ``title``, its figures read from ``out``."""
    body = []
    for block in blocks:
        kind = block[0]
        if kind in ("h1", "h2", "p"):
            body.append(f"<{kind}>{html.escape(block[1])}</{kind}>")
        elif kind == "table":
            head = "".join(f"<th>{html.escape(cell)}</th>" for cell in block[1])
            rows = "".join(
                "<tr>" + "".join(f"<td>{html.escape(cell)}</td>" for cell in row) + "</tr>" for row in block[2]
            )
            body.append(f"<table><thead><tr>{head}</tr></thead><tbody>{rows}</tbody></table>")
        elif kind == "figure":
            data = base64.b64encode((out / block[1]).read_bytes()).decode("ascii")
            body.append(
                f'<figure><img alt="{html.escape(block[2])}" src="data:image/png;base64,{data}">'
                f"<figcaption>{html.escape(block[2])}</figcaption></figure>"
            )
    style = (
        f"body{{font-family:sans-serif;max-width:{COLUMN_PX}px;margin:2em auto;line-height:1.4}}"
        "table{border-collapse:collapse;margin:1em 0;font-size:90%}td,th{border:1px solid #bbb;padding:3px 6px}"
        "th{background:#eee}figure{margin:1em 0}img{max-width:100%}figcaption{font-style:italic}"
    )
    return (
        f'<!DOCTYPE html>\n<html><head><meta charset="utf-8"><title>{html.escape(title)}</title>'
        f"<style>{style}</style></head><body>\n" + "\n".join(body) + "\n</body></html>\n"
    )
