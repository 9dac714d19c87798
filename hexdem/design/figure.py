"""``design.png``: where the best design's sensors are, beside the paper's configurations, and each
key's expected 90 % width for each."""

from __future__ import annotations

import numpy as np

from hexdem.analysis.plotting import plain_log_ticks, save, subplots
from hexdem.calibration.plots import axis_label
from hexdem.design.criterion import prior_moments
from hexdem.model.config import RunConfig
from hexdem.model.model_builder import build_model
from hexdem.model.sensors import sensor_beads

#: How each design is drawn: marker, colour.
STYLES = {"best": ("*", "crimson"), "1": ("o", "tab:blue"), "2": ("s", "tab:green"), "3": ("D", "tab:orange")}


def design_figure(problem, best: dict, paper: dict | None, priors, records: int, path) -> None:
    """The packing of ``problem``'s base with ``best``'s sensors (a row of ``design.csv``) and the
    paper's configurations (``design.json``'s ``paper_configurations``, or None) marked; beside it,
    each key's expected 90 % width over its prior's, per design, with ``records`` records."""
    config = RunConfig.from_dict(problem.base | {"sensors": []}, source="--config")
    model = build_model(config)
    packing = model.packing
    designs = {"best": best["sensors"].split()}
    widths = {"best": [best[f"width_{prior.key}"] for prior in priors]}
    for name, entry in (paper or {}).items():
        if entry is not None:
            designs[name], widths[name] = entry["sensors"], [entry["widths"][prior.key] for prior in priors]
    fig, (where, bars) = subplots(1, 2, figsize=(11, 5), layout="constrained", width_ratios=(1.2, 1))
    xy = packing.positions_m * 1e3
    where.scatter(xy[:, 0], xy[:, 1], s=18, facecolors="none", edgecolors="0.75", linewidths=0.6)
    struck = model.struck_beads[0]
    where.scatter(*xy[struck], s=60, color="black", marker="v", label="struck bead")
    for name, sensors in designs.items():
        beads = list(sensor_beads([int(s) if s.isdigit() else s for s in sensors], packing).values())
        marker, colour = STYLES[name]
        label = f"best: {' '.join(sensors)} at {best['v_striker']:g}" if name == "best" else f"configuration {name}"
        where.scatter(
            xy[beads, 0],
            xy[beads, 1],
            s=110 if name == "best" else 50,
            marker=marker,
            facecolors=colour if name == "best" else "none",
            edgecolors=colour,
            linewidths=1.4,
            label=label,
        )
    where.set_aspect("equal")
    where.set_xlabel("x [mm]")
    where.set_ylabel("y [mm]")
    where.legend(loc="upper left", fontsize=8, bbox_to_anchor=(0.0, -0.12), ncol=2, frameon=False)
    prior_widths = np.array([prior_moments(prior)[2] for prior in priors])
    step = 0.8 / len(widths)
    for j, (name, values) in enumerate(widths.items()):
        marker, colour = STYLES[name]
        bars.bar(
            np.arange(len(priors)) + j * step,
            np.asarray(values) / prior_widths,
            step,
            color=colour,
            label="best" if name == "best" else f"configuration {name}",
        )
    bars.set_xticks(np.arange(len(priors)) + 0.4 - step / 2, [axis_label(prior.key)[0] for prior in priors])
    bars.set_ylabel("expected 90 % width / prior's 90 % width")
    ratios = np.array(list(widths.values())) / prior_widths
    bars.set_yscale("log")
    bars.set_ylim(min(float(np.min(ratios)) / 2, 0.5), 1.5)
    plain_log_ticks(bars.yaxis)
    bars.axhline(1.0, color="0.5", linewidth=0.8, linestyle=":")
    bars.legend(fontsize=8)
    bars.set_title(f"what {records} record(s) would tell, each design at {best['v_striker']:g}", fontsize=10)
    save(fig, path)
