"""The self-similarity study's files: ``self_similarity.csv`` and ``.json``, ``chain.json``, the
figures and an HTML page (:mod:`hexdem.paper.self_similarity`, :mod:`hexdem.theory.chain_wave`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hexdem.common.io import write_csv, write_json, write_text
from hexdem.paper.self_similarity import COLLAPSE_TOLERANCE, Ray

#: Columns of ``self_similarity.csv`` (a contract).
COLUMNS = ("study", "line", "n", "distance_d", "peak_speed", "width_s", "arrival_time_s", "profile_residual")
#: The criterion of ``self_similar``, as stated in the JSON.
CRITERION = (
    f"the profiles v/v_m against (t - t_a)/w of the middle third of the fit range lie within {COLLAPSE_TOLERANCE:g} "
    "(RMS, in units of the peak; median over the beads) of the mean profile of its outer third"
)


def rows(measured: dict[str, dict[str, Ray]]) -> list[tuple]:
    """Rows of ``self_similarity.csv`` from {study: {line: Ray}}."""
    return [
        (
            study,
            line,
            n,
            float(ray.distance_d[n]),
            float(ray.peak_speed[n]),
            float(ray.width_s[n]),
            float(ray.arrival_time_s[n]),
            float(ray.profile_residual[n]),
        )
        for study, rays in measured.items()
        for line, ray in rays.items()
        for n in range(len(ray.distance_d))
    ]


def energy_verdict(value: float, stderr: float) -> str:
    """Does the leading pulse keep the energy it carries across a ring along this ray (:math:`r^e`, e = 0
    within two standard errors), leak it into its tail, or gain it from the neighbouring
    directions (the budget is per unit angle)? "undetermined" without a finite fit."""
    if not (np.isfinite(value) and np.isfinite(stderr)):
        return "undetermined"
    if abs(value) <= 2 * stderr:
        return "keeps its energy"
    if value < 0:
        return f"leaks energy into its tail: what it carries falls as r^{value:.2f}"
    return f"draws energy from the neighbouring directions: what it carries grows as r^{value:.2f}"


def summary(measured: dict[str, dict[str, Ray]]) -> dict:
    """``self_similarity.json``: per study and line the exponents with their standard errors,
    the fit range, the collapse residual, ``self_similar`` and the energy budget."""
    result = {"criterion": CRITERION, "collapse_tolerance": COLLAPSE_TOLERANCE}
    for study, rays in measured.items():
        result[study] = {}
        for line, ray in rays.items():
            energy, energy_se = ray.energy_exponent()
            result[study][line] = {
                **{
                    f"{name}_exponent": {"value": value, "stderr": stderr}
                    for name, (value, stderr) in ray.exponents.items()
                },
                "fit_range_d": list(ray.fit_range_d),
                "collapse_residual": ray.middle_residual,
                "self_similar": ray.self_similar,
                "energy_exponent": {"value": energy, "stderr": energy_se},
                "energy_verdict": energy_verdict(energy, energy_se),
            }
    return result


def verdict(result: dict, study: str) -> str:
    """One sentence on ``study``: self-similar or not along each ray, with the exponents."""
    lines = result[study]
    similar = [line for line, entry in lines.items() if entry["self_similar"]]

    def exponent(entry, name):
        return f"{entry[name]['value']:+.3f} ± {entry[name]['stderr']:.3f}"

    details = "; ".join(
        f"{line}°: v_m ∝ r^({exponent(e, 'amplitude_exponent')}), w ∝ r^({exponent(e, 'width_exponent')}), "
        f"c ∝ r^({exponent(e, 'speed_exponent')}), collapse residual {e['collapse_residual']:.3f}, "
        f"{e['energy_verdict']}"
        for line, e in lines.items()
    )
    if len(similar) == len(lines):
        head = f"The {study} pulse approaches a self-similar form along every ray"
    elif similar:
        head = f"The {study} pulse is self-similar along {', '.join(s + '°' for s in similar)} only"
    else:
        head = f"The {study} pulse does not approach a self-similar form"
    return f"{head} ({details})."


def figures(measured: dict[str, dict[str, Ray]], out: Path) -> None:
    """``self_similarity.png`` (amplitude, width, front speed and collapse residual against r,
    log-log, every study and ray) and ``profiles.png`` (each study's profiles along 0°, coloured
    by distance)."""
    from matplotlib import colormaps

    from hexdem.analysis import plotting as plots
    from hexdem.analysis.pulse_shape import PROFILE_GRID

    fig, axes = plots.subplots(2, 2, figsize=(11, 8.5), layout="constrained")
    panels = (
        ("peak_speed", r"leading-pulse amplitude $v_m$ [m/s]"),
        ("width_s", "width at half maximum $w$ [s]"),
        ("front_speed_m_s", "local front speed $c$ [m/s]"),
        ("profile_residual", "profile's RMS distance from the outer shape"),
    )
    styles = {"uncompressed": "-", "precompressed": "--"}
    for ax, (name, label) in zip(axes.flat, panels):
        for study, rays in measured.items():
            for k, (line, ray) in enumerate(rays.items()):
                ax.plot(
                    ray.distance_d, np.abs(getattr(ray, name)), styles[study], color=f"C{k}", label=f"{study}, {line}°"
                )
        ax.set_xscale("log")
        ax.set_yscale("log")
        plots.plain_log_ticks(ax.xaxis)
        plots.plain_log_ticks(ax.yaxis)
        ax.set_xlabel("distance $r$ [d]")
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
    axes[1, 1].axhline(COLLAPSE_TOLERANCE, color="k", lw=0.8)
    axes[0, 0].legend(fontsize=7)
    fig.suptitle("The leading pulse against distance: solid uncompressed, dashed the precompressed control")
    plots.save(fig, out / "self_similarity.png")
    fig, axes = plots.subplots(
        1, len(measured), figsize=(5.5 * len(measured), 4.2), squeeze=False, layout="constrained"
    )
    for ax, (study, rays) in zip(axes[0], measured.items()):
        ray = rays["0"]
        colours = colormaps["viridis"](np.linspace(0, 1, len(ray.distance_d)))
        for profile, colour in zip(ray.profiles, colours):
            ax.plot(PROFILE_GRID, profile, color=colour, lw=0.8)
        ax.set_xlabel("$(t - t_a)/w$")
        ax.set_ylabel("$v/v_m$")
        ax.set_title(
            f"{study}, 0°: {ray.distance_d[0]:.0f} d (purple) to {ray.distance_d[-1]:.0f} d (yellow)", fontsize=9
        )
        ax.grid(True, alpha=0.3)
    plots.save(fig, out / "profiles.png")


def chain_figure(chain_rows: dict, hexagon_rows: dict, path) -> None:
    """Peak speed over V0 against distance: the chain's unchanged pulse beside the hexagon's
    decay along its 0° and ±30° lines ({label: (distance_d, peak / V0)})."""
    from hexdem.analysis import plotting as plots

    fig, ax = plots.subplots(figsize=(6.4, 4.6), layout="constrained")
    for label, (distance, ratio) in {**chain_rows, **hexagon_rows}.items():
        ax.plot(distance, ratio, "o-", markersize=3, label=label)
    ax.set_yscale("log")
    plots.plain_log_ticks(ax.yaxis)
    ax.set_xlabel("distance from the struck bead [d]")
    ax.set_ylabel("peak speed / V₀")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("A chain's solitary wave against the hexagon's decaying pulse")
    plots.save(fig, path)


def write_page(out: Path, result: dict, chain: dict, late_rise: dict | None = None) -> None:
    """``self_similarity.html``, one self-contained page with the verdicts and figures."""
    from hexdem.common.html_page import render_html

    blocks = [
        ("h1", "Does the decaying pulse become self-similar?"),
        *[("p", verdict(result, study)) for study in result if study not in ("criterion", "collapse_tolerance")],
        ("p", f"Criterion: {CRITERION}."),
        ("figure", "self_similarity.png", "The leading pulse's amplitude, width, front speed and collapse against r"),
        ("figure", "profiles.png", "Profiles v/v_m against (t − t_a)/w along 0°"),
        ("h2", "A chain's solitary wave beside it"),
        (
            "p",
            f"The 80-bead chain's pulse keeps its amplitude (last / first bead {chain['peak_ratio']:.6f}) and runs at "
            f"{chain['front_speed_m_s']:.1f} m/s against Nesterenko's {chain['nesterenko_speed_m_s']:.1f} m/s "
            f"({100 * chain['relative_deviation']:+.2f} %); at half maximum it spans "
            f"{chain['half_maximum_width_d']:.2f} d against the continuum's "
            f"{chain['continuum_half_maximum_width_d']:.2f} d "
            f"(of a pulse {chain['continuum_support_width_d']:.2f} d long).",
        ),
        ("figure", "chain.png", "Peak speed along a chain and along the hexagon's lines"),
    ]
    if late_rise:
        blocks += [
            ("h2", "The late rise of the front's anisotropy"),
            ("p", late_rise["verdict"]),
            ("figure", "late_rise.png", "a6/a0 against the front's radius, as measured four ways"),
        ]
    write_text(out / "self_similarity.html", render_html(blocks, out, "hexdem: self-similarity of the decaying pulse"))


def write_outputs(out: Path, measured: dict, chain: dict) -> dict:
    """The CSV, the JSONs and the figures; the study's summary."""
    write_csv(out / "self_similarity.csv", COLUMNS, rows(measured))
    result = summary(measured)
    write_json(out / "self_similarity.json", result)
    write_json(out / "chain.json", chain)
    figures(measured, out)
    return result
