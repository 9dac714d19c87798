"""The report of ``hexdem paper``: ``report.md``, ``report.html`` and ``published_vs_computed.csv``.

The report is built once as a list of blocks (headings, paragraphs, tables, figures) and
rendered twice: Markdown that links the PNGs beside it, and a self-contained HTML page with
the figures embedded (base64), which opens in any browser without the folder.
"""

from __future__ import annotations

import json
import platform
from datetime import UTC, datetime
from importlib.metadata import version
from pathlib import Path

from hexdem.analysis.leading_pulse import LEAD_FALL, LEAD_THRESHOLD
from hexdem.common.html_page import render_html
from hexdem.common.io import write_csv, write_text
from hexdem.disorder.preparation import TOLERANCE_M
from hexdem.paper.comparison import (
    COMPARISON_COLUMNS,
    comparison_rows,
    largest_differences,
)
from hexdem.paper.crossover import (
    CROSSOVER_FIGURES,
    FIT_TABLE_HEADER,
    OVERLAP_TABLE_HEADER,
    fit_table,
    impact_overlap_m,
    overlap_table,
)
from hexdem.paper.settings import STUDY_VELOCITY_M_S
from hexdem.theory.protocols import CONSISTENT_SIGMAS, MIN_V0, STARTS

#: The paper's figures as hexdem draws them: (file under DIR, caption).
PAPER_FIGURES = (
    ("fig3/fig3_smallsim.png", "Fig. 3: wavefront in the 11-per-edge hexagon, striker at 0.40 m/s"),
    ("fig4/fig4_largesim.png", "Fig. 4: wavefront in the half-hexagon, the small hexagon's walls dashed"),
    ("tca/fig5a_pulse_speed.png", "Fig. 5a: pulse speeds along the 30° line, lattice vs TCA (V0 = 0.1)"),
    ("tca/fig5b_arrival_time.png", "Fig. 5b: arrival times along the 30° line of the experiment (0.40 m/s)"),
    ("scaling/fig6_vodecay30.png", "Fig. 6: 30° strike, the decay fits and laws"),
    ("scaling/fig7_vodecay0.png", "Fig. 7: 0° strike, the decay fits and laws"),
    ("disorder/sigma6tol/fig8_expnumsim_v0.400.png", "Fig. 8: arrival maps, ideal vs weak disorder (0.40 m/s)"),
    ("disorder/sigma6tol/fig9_all_directions.png", "Fig. 9: peak speed along 0° and −30°, disorder vs ideal"),
)


def _fmt(value, digits: int = 4) -> str:
    if value is None:
        return "–"
    if isinstance(value, float):
        return f"{value:.{digits}g}"
    return str(value)


def _comparison_blocks(rows: list[tuple]) -> list:
    worst = largest_differences(rows)
    table = [(r[0], r[1], _fmt(r[3]), _fmt(r[4]), f"{r[5]:+.4f}", f"{100 * r[5] / r[3]:+.1f} %") for r in rows]
    return [
        ("h2", "1. Published numbers beside hexdem's"),
        (
            "p",
            "Every number the paper publishes, with hexdem's under the protocol the paper states "
            "(the protocol of each row is in published_vs_computed.csv). Largest relative differences: "
            + "; ".join(f"{r[0]} {r[1]}: {_fmt(r[4])} vs {_fmt(r[3])} ({100 * r[5] / r[3]:+.0f} %)" for r in worst)
            + ".",
        ),
        ("table", ("item", "quantity", "published", "hexdem", "difference", "relative"), table),
    ]


def _protocol_blocks(protocols: dict) -> list:
    table, notes = [], []
    for name, s in protocols.items():
        stated, closest, consistent = s["stated"], s["closest"], s["consistent"]
        table.append(
            (
                name,
                f"{_fmt(s['published']['m'])}, {_fmt(s['published']['b'])}",
                f"{stated['m']:.4f} ± {stated['m_stderr']:.4f}, {stated['b']:.4f} ± {stated['b_stderr']:.4f}",
                closest["description"],
                f"{closest['m']:.4f}, {closest['b']:.4f}",
                f"{100 * closest['distance']:.2f} %",
                f"{consistent['count']} of {s['protocols']}",
            )
        )
        if consistent["count"]:
            notes.append(
                f"{name}: {consistent['count']} protocol{'s are' if consistent['count'] > 1 else ' is'} "
                "consistent; of these "
                f"{100 * consistent['anchored']:.0f} % anchor the start, "
                f"{100 * consistent['fit_loglinear']:.0f} % fit log-linearly, windows end at beads "
                f"{consistent['last_range'][0]}–{consistent['last_range'][1]}, V0 ranges start in "
                f"{consistent['v0_min_range'][0]:.3g}–{consistent['v0_min_range'][1]:.3g} and end in "
                f"{consistent['v0_max_range'][0]:.3g}–{consistent['v0_max_range'][1]:.3g}"
                + (" (the stated protocol is among them)" if stated["consistent"] else " (the stated protocol is not)")
                + "."
            )
        else:
            notes.append(f"{name}: no protocol is consistent with the published (m, b).")
    return [
        ("h2", "2. The fit protocol"),
        (
            "p",
            "The paper does not say over which beads, which V0 or how it fitted c(V0) = m V0 + b. Every "
            f"protocol (first bead {min(STARTS)}–{max(STARTS)}, last bead, anchored or free start, log-linear "
            f"or nonlinear, any contiguous range of at least {MIN_V0} of the sweep's V0) was fitted to the "
            f"same sweep. Consistent: m and b both within {CONSISTENT_SIGMAS:g} standard errors plus half a "
            "unit of the published last digit. With "
            "tens of thousands of protocols a close match somewhere is likely by chance: what the "
            "consistent protocols share is the informative part.",
        ),
        (
            "table",
            (
                "combination",
                "published m, b",
                "stated protocol m, b (± 1 SE)",
                "closest protocol",
                "its m, b",
                "distance",
                "consistent",
            ),
            table,
        ),
        *[("p", note) for note in notes],
        ("figure", "fit_protocols/fit_protocols.png", "(m, b) of every protocol against the published point"),
    ]


def _prestress_finding(rows: list[dict]) -> str:
    """One sentence comparing the walls' load with and without the prestress, per σ of the variant."""
    load = {(r["sigma_per_tol"], r["preparation"]): r["wall_force_n"] for r in rows}
    pairs = sorted(s for s, preparation in load if preparation == "relaxed" and (s, "prestressed") in load)
    return " ".join(
        f"At σ = {s:g} tol the walls carry {load[(s, 'prestressed')]:.3g} N after the paper's "
        f"preparation and {load[(s, 'relaxed')]:.3g} N with the walls stood back."
        for s in pairs
    )


def _ratio(value, sem=None) -> str:
    """A transmission ratio to 3 decimals, ± its standard error if any, "–" if missing."""
    if value is None:
        return "–"
    return f"{value:.3f}" + (f" ± {sem:.3f}" if sem is not None else "")


def _lead_coverage(study: dict) -> str:
    """How many line beads had a leading pulse at all (the others are left out of 'lead')."""
    fractions = [f for name, f in study["leading_pulse_defined_fraction"].items() if not name.startswith("sigma0tol")]
    if not fractions:
        return ""
    return (
        f"A leading pulse was found for {100 * min(fractions):.0f}–{100 * max(fractions):.0f} % of the line "
        "beads (n ≥ 2) of the disordered realizations; 'lead' averages over those."
    )


def _disorder_blocks(study: dict) -> list:
    rows = [
        (
            _fmt(r["sigma_per_tol"]),
            r["preparation"],
            r["measure"],
            r["line"],
            _ratio(r["ratio_to_ideal"], r["sem"]),
            str(r["realizations"]),
            _ratio(r["ratio_to_equal_beads"]),
        )
        for r in study["rows"]
    ]
    prestress = [
        (
            _fmt(r["sigma_per_tol"]),
            r["preparation"],
            f"{r['mean_contact_force_n']:.3g}",
            f"{r['max_contact_force_n']:.3g}",
            f"{r['wall_force_n']:.3g}",
        )
        for r in study["prestress"]
    ]
    return [
        ("h2", "3. Weak disorder: does transmission along ±30° rise?"),
        ("p", f"Verdict: {study['verdict']['summary']}"),
        (
            "p",
            "Transmission: mean over beads n ≥ 2 of V_n / V_n(ideal) per realization, mean ± standard error "
            f"over realizations, striker at {STUDY_VELOCITY_M_S:.2f} m/s. 'peak' is the maximum over the run, "
            "'lead' the leading pulse's amplitude (its first maximum that reaches "
            f"{100 * LEAD_THRESHOLD:.0f} % of the bead's largest speed and is followed by a fall below "
            f"{100 * LEAD_FALL:.0f} % of itself). 'relaxed' stands the walls back so that no "
            "prestress remains; 'over equal beads' divides by the σ = 0 packing prepared the same way. "
            "σ = 0 has one realization: equal beads prepared the same way are identical (LAMMPS is "
            "deterministic on one rank), so its ratio is exact. " + _lead_coverage(study),
        ),
        (
            "table",
            ("σ / tol", "preparation", "measure", "line", "disordered / ideal", "realizations", "over equal beads"),
            rows,
        ),
        (
            "p",
            "Prestress the packings keep after the preparation (mean over realizations). "
            + _prestress_finding(study["prestress"]),
        ),
        (
            "table",
            ("σ / tol", "preparation", "mean contact force [N]", "max contact force [N]", "total wall force [N]"),
            prestress,
        ),
        ("figure", "disorder/disorder_study.png", "Transmission against disorder strength"),
    ]


def _crossover_blocks(crossover: dict) -> list:
    """Section 3b: the crossover sweep's fits, the V^(4/5) test and the ±30° claim in its terms."""
    sigmas = ", ".join(f"{s:g}" for s in crossover["sigma_per_tol"])
    return [
        ("h2", "3b. Weak disorder across the contact scale: where the ideal lattice stops"),
        (
            "p",
            f"σ / tol = {sigmas}, each ensemble prepared as the paper's and struck at "
            + ", ".join(f"{v:.2f}" for v in crossover["velocities_m_s"])
            + " m/s. δ(V), the largest overlap of two beads meeting at the striker speed, is "
            + ", ".join(f"{impact_overlap_m(v) / TOLERANCE_M:.2f}" for v in crossover["velocities_m_s"])
            + " tol at these speeds. Each (speed, line, measure) is fitted with a step in "
            "log σ, T = T∞ + (T₀ − T∞) / (1 + (σ/σ_c)ᵖ), weighted by the standard errors; σ_c is "
            "the σ at half the drop, ± its standard error.",
        ),
        ("p", f"Verdict: {crossover['verdict']}"),
        ("table", FIT_TABLE_HEADER, fit_table(crossover["fits"])),
        (
            "p",
            "The overlap hypothesis: σ_c ∝ V to the power 4/5 if the impact's overlap sets the crossover "
            "(slope of log σ_c against log V, ± its standard error; consistent = within two).",
        ),
        ("table", OVERLAP_TABLE_HEADER, overlap_table(crossover["overlap_test"])),
        ("p", f"The paper's ±30° claim in these terms: {crossover['pm30_claim']}"),
        ("figure", f"disorder/{CROSSOVER_FIGURES['tol']}", "Transmission against σ"),
        (
            "figure",
            f"disorder/{CROSSOVER_FIGURES['overlap']}",
            "Transmission against σ / δ(V): if the impact's overlap sets the crossover, the speeds collapse",
        ),
    ]


def _friction_blocks(friction: dict) -> list:
    """Section 3c: what Mindlin friction does to the experiment's pulses, decay and disorder."""
    effect = [
        (
            _fmt(r["friction"]),
            _fmt(r["sigma_tol"]),
            r["line"],
            _ratio(r["mean_peak_ratio"], None if r["sigma_tol"] == 0 else r["sem_peak_ratio"]),
            f"{r['mean_arrival_shift_us']:+.2f}",
        )
        for r in friction["rows"]
        if abs(r["v_striker"] - STUDY_VELOCITY_M_S) < 1e-9 and r["friction"] > 0
    ]
    decay = [
        (
            _fmt(r["friction"]),
            f"{r['v_striker']:.2f}",
            r["combination"],
            f"{r['decay_rate']:.4f} ± {r['decay_rate_stderr']:.4f}",
            f"{r['ratio_to_frictionless']:.4f}",
        )
        for r in friction["decay"]
        if abs(r["v_striker"] - STUDY_VELOCITY_M_S) < 1e-9
    ]
    return [
        ("h2", "3c. Friction and rotation"),
        (
            "p",
            "The beads rub and roll: Hertz's normal force with Mindlin's tangential force (no-slip stiffness "
            "8 G* a, with history, capped at μ times the normal force), every bead and the striker turning "
            "about z as solid spheres, the walls with the same law and their own E* and G*. The preparation "
            "stays frictionless, so each μ strikes the very packings the paper's σ = 6 tol ensemble "
            f"strikes: the first {friction['realizations']} of its {friction['paper_realizations']} "
            "(fewer, to keep the whole paper within ten minutes on two workers; μ = 0 is read on the "
            "same packings). Ratios and shifts are "
            "to the frictionless run of the same packing and speed, averaged over the line's beads "
            "n ≥ 2 (± standard error over packings); the leading pulse's amplitude is the measure.",
        ),
        ("p", f"Arrival times: {friction['arrival_verdict']}"),
        ("p", f"Disorder: {friction['disorder_verdict']}"),
        (
            "table",
            (
                "μ",
                "σ / tol",
                "line",
                f"leading pulse / frictionless at {STUDY_VELOCITY_M_S:.2f} m/s",
                "arrival shift [µs]",
            ),
            effect,
        ),
        (
            "p",
            "Sec. V's decay rate c (Vₙ = Vₛ cⁿ⁻ˢ, the anchored log-linear fit) of the ideal lattice's "
            "leading pulses, for the 0° strike along 0° (s = 2) and +30° (s = 1), to the last bead no wall "
            f"touches, at {STUDY_VELOCITY_M_S:.2f} m/s (friction/friction_decay.csv has every speed: "
            "Hertz–Mindlin–Coulomb contacts are scale invariant, and the rates agree to 1e-4).",
        ),
        ("table", ("μ", "V [m/s]", "combination", "c (± 1 SE)", "c(μ) / c(0)"), decay),
        ("figure", "friction/friction_effect.png", "Friction against the frictionless spheres"),
    ]


def _header_blocks(out: Path, settings, wall_time_s: float) -> list:
    parts = sorted((out / "parts").glob("*.json"))
    times = [(p.stem, f"{json.loads(p.read_text())['wall_time_s']:.1f}") for p in parts]
    lammps = json.loads((out / "fig3" / "snapshots.json").read_text())["lammps_version"]
    return [
        ("h1", "hexdem: Traveling Waves in 2D Hexagonal Granular Crystal Lattices, reproduced"),
        (
            "p",
            f"hexdem {version('hexdem')}, {lammps}, Python {platform.python_version()} on "
            f"{platform.machine()} ({platform.node()}), "
            f"{datetime.now(UTC).strftime('%Y-%m-%d %H:%M UTC')}. "
            f"{'Quick run (thinned sweep and ensembles: rough numbers)' if settings.quick else 'Full run'}, "
            f"{settings.workers} worker{'s' if settings.workers != 1 else ''}; this invocation {wall_time_s:.0f} "
            f"s. Parts (s, when computed): " + ", ".join(f"{name} {t}" for name, t in times) + ".",
        ),
    ]


def build_report(out: Path, settings, summaries: dict, wall_time_s: float) -> tuple[list, list[tuple]]:
    """(blocks, rows of published_vs_computed.csv)."""
    scaling = json.loads((out / "scaling" / "scaling.json").read_text())
    rows = comparison_rows(summaries["tca"], scaling, summaries["fit_protocols"])
    blocks = [
        *_header_blocks(out, settings, wall_time_s),
        *_comparison_blocks(rows),
        *_protocol_blocks(summaries["fit_protocols"]),
        *_disorder_blocks(summaries["disorder"]),
        *_crossover_blocks(summaries["crossover"]),
        *_friction_blocks(summaries["friction"]),
        ("h2", "4. The paper's figures"),
        *[("figure", path, caption) for path, caption in PAPER_FIGURES if (out / path).exists()],
    ]
    return blocks, rows


def render_markdown(blocks: list) -> str:
    lines = []
    for block in blocks:
        kind = block[0]
        if kind in ("h1", "h2"):
            lines += ["#" * int(kind[1]) + " " + block[1], ""]
        elif kind == "p":
            lines += [block[1], ""]
        elif kind == "table":
            header, rows = block[1], block[2]
            lines += ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
            lines += ["| " + " | ".join(cell.replace("|", "\\|") for cell in row) + " |" for row in rows] + [""]
        elif kind == "figure":
            lines += [f"![{block[2]}]({block[1]})", "", f"*{block[2]}*", ""]
    return "\n".join(lines)


def write_report(out: Path, settings, summaries: dict, wall_time_s: float) -> list[tuple]:
    """Write ``published_vs_computed.csv``, ``report.md`` and ``report.html`` into ``out``."""
    blocks, rows = build_report(out, settings, summaries, wall_time_s)
    write_csv(out / "published_vs_computed.csv", COMPARISON_COLUMNS, rows)
    write_text(out / "report.md", render_markdown(blocks))
    write_text(out / "report.html", render_html(blocks, out, "hexdem paper report"))
    return rows
