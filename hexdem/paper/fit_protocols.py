"""The fit-protocol search of ``hexdem paper``, run on the sweep of its scaling step.

For each strike/observation combination every protocol of :mod:`hexdem.theory.protocols` is
fitted to the sweep's peak speeds (read back from ``peaks.csv``: no new simulation) and
compared with the paper's (m, b). Writes ``fit_protocols.csv`` (per combination the paper's
stated protocol, then the :data:`CLOSEST` nearest ones), ``fit_protocols.json`` and
``fit_protocols.png`` (every protocol's (m, b) beside the published point).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hexdem.common.io import write_csv, write_json
from hexdem.paper.published import published
from hexdem.theory.outputs import complete_beads, read_sweep_peaks
from hexdem.theory.protocols import PROTOCOL_COLUMNS, ProtocolSearch, Target, search_protocols
from hexdem.theory.scaling import COMBINATIONS, DEFAULT_LAST

#: Nearest protocols listed per combination.
CLOSEST = 10


def target(combination: str) -> Target:
    m, b = published("m", combination), published("b", combination)
    return Target(m.value, b.value, m.rounding, b.rounding)


def stated_protocol(search: ProtocolSearch) -> int:
    """The paper's own reading: start bead of its law, beads up to 12, anchored, log-linear, all V₀."""
    start = COMBINATIONS[search.combination].start
    return search.find(start, DEFAULT_LAST, True, "loglinear", 0, len(search.v0) - 1)


def describe(search: ProtocolSearch, i: int) -> str:
    """One protocol in words, as the report and the published-vs-computed table quote it."""
    row = dict(zip(PROTOCOL_COLUMNS, search.row(i)))
    start = f"anchored V_{row['start']}" if row["anchored"] else f"free V_{row['start']}"
    return (
        f"{start}, beads {row['start']}..{row['last']}, {row['fit']} fit, "
        f"V0 {row['v0_min']:.3g}..{row['v0_max']:.3g} ({row['n_v0']} values)"
    )


def run_search(scaling_dir, out) -> dict:
    """Search every combination's protocols on ``scaling_dir/peaks.csv``; write the files into
    ``out`` and return the summary (``fit_protocols.json``)."""
    out = Path(out)
    v0, peaks = read_sweep_peaks(scaling_dir)
    searches, summary, rows = {}, {}, []
    for name in COMBINATIONS:
        max_last = complete_beads(peaks[name]) - 1
        search = search_protocols(name, v0, peaks[name][:, : max_last + 1], target(name), max_last)
        searches[name] = search
        stated, closest = stated_protocol(search), search.closest(CLOSEST)
        rows += [("stated", *search.row(stated))] + [
            (f"closest_{k + 1}", *search.row(i)) for k, i in enumerate(closest)
        ]
        summary[name] = {
            "published": {"m": target(name).m, "b": target(name).b},
            "protocols": len(search),
            "stated": {**dict(zip(PROTOCOL_COLUMNS, search.row(stated))), "description": describe(search, stated)},
            "closest": {
                **dict(zip(PROTOCOL_COLUMNS, search.row(closest[0]))),
                "description": describe(search, closest[0]),
            },
            "consistent": search.consistent_shares(),
        }
    write_csv(out / "fit_protocols.csv", ("role", *PROTOCOL_COLUMNS), rows)
    write_json(out / "fit_protocols.json", summary)
    protocol_figure(searches, out / "fit_protocols.png")
    return summary


def protocol_figure(searches: dict, path) -> None:
    """(m, b) of every protocol per combination (anchored and free starts), the paper's stated
    protocol, the closest one and the published point."""

    from hexdem.analysis import plotting as plots

    fig, axes = plots.subplots(2, 2, figsize=(11, 8.5), layout="constrained")
    for ax, (name, search) in zip(axes.ravel(), searches.items()):
        for anchored, colour, label in ((True, "C0", "anchored start"), (False, "C1", "free start")):
            chosen = search.anchored == anchored
            ax.scatter(search.m[chosen], search.b[chosen], s=2, alpha=0.15, color=colour, rasterized=True, label=label)
        stated, closest, t = stated_protocol(search), search.closest()[0], target(name)
        ax.errorbar(
            search.m[stated],
            search.b[stated],
            xerr=2 * search.m_stderr[stated],
            yerr=2 * search.b_stderr[stated],
            fmt="D",
            color="k",
            capsize=3,
            label="paper's stated protocol (± 2 SE)",
        )
        ax.plot(t.m, t.b, "r*", markersize=12, label="published")
        ax.plot(
            search.m[closest],
            search.b[closest],
            "^",
            markersize=9,
            markerfacecolor="none",
            markeredgecolor="g",
            markeredgewidth=1.5,
            label="closest protocol",
        )
        for values, mark, axis_limits in (
            (search.m, (t.m, search.m[stated]), ax.set_xlim),
            (search.b, (t.b, search.b[stated]), ax.set_ylim),
        ):
            low, high = np.percentile(values, [5, 95])
            low, high = min(low, *mark), max(high, *mark)
            axis_limits(low - 0.05 * (high - low), high + 0.05 * (high - low))
        ax.set_title(f"{name} (strike/observation), {len(search)} protocols", fontsize=10)
        ax.set_xlabel("$m$")
        ax.set_ylabel("$b$")
        ax.grid(True, alpha=0.3)
    axes[0, 0].legend(fontsize=8)
    fig.suptitle(r"$c(V_0) = m V_0 + b$ under every fit protocol (central 90 % shown), against the paper's $(m, b)$")
    plots.save(fig, path)
