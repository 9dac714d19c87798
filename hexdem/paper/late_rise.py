"""The late rise of the front's sixfold anisotropy: physics, or an artefact?

The front study (:mod:`hexdem.experiments.front_study`) finds the uncompressed front's a6/a0
falling to about −0.002 by 80 d and growing again beyond 100 d, to −0.0029 at 159 d, a rise its
fitted law :math:`A_∞ + B R^{−p}` does not follow. An artefact of the discretization, of the sampling or
of the half-maximum measure would change when that is refined or replaced. The same half-disc
is therefore measured four ways (:data:`VARIANTS`):

* ``baseline``: the front study's run (140 steps per contact, a sample every 7 steps) and its
  half-maximum front;
* ``finer_sampling``: a sample every 3 steps (2.3 times finer);
* ``finer_step``: 280 steps per contact, sampled at the same times;
* ``fixed_speed``: the baseline run, its front the first crossing of a fixed small speed,
  :data:`THRESHOLD_FRACTION` of V0 (the pulse's very foot rather than its half maximum).

For each: a6/a0 against the front's mean radius R, the fit :math:`A_∞ + B R^{−p}` over the front study's
range, and the **late rise**: the mean a6/a0 of the fronts beyond :data:`OUTER` of the largest
radius measured (within that range) minus the mean over :data:`PLATEAU` of it (negative: the
anisotropy grows again).

**Verdict** (:func:`verdict`): there is no late rise if the baseline's is not negative by more
than twice its fitted A∞'s standard error; otherwise the rise is a sampling or time-step
artefact if refining either changes it by more than :data:`RISE_AGREEMENT` of itself; it belongs
to the half-maximum measure if the fixed-speed front's rise is less than that fraction of it or
of the other sign; else it is the front's own.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hexdem.analysis.roundness_fit import fit_roundness
from hexdem.experiments.front_study import FrontStudy, study_front_shape
from hexdem.experiments.run import simulate

#: The four measurements: name → (changes to the run's configuration, front measure).
VARIANTS = {
    "baseline": ({}, "half_maximum"),
    "finer_sampling": ({"dump_every": 3}, "half_maximum"),
    "finer_step": ({"steps_per_contact": 280, "dump_every": 14}, "half_maximum"),
    "fixed_speed": ({}, "fixed_speed"),
}
#: The fixed speed of the second measure, as a fraction of V0.
THRESHOLD_FRACTION = 1e-3
#: Fractions of the largest fitted radius: the plateau and the outer fronts of the late rise.
PLATEAU = (0.5, 0.7)
OUTER = (0.85, 1.0)
#: Refinements that change the rise by less than this fraction of it leave it standing.
RISE_AGREEMENT = 0.3
#: Columns of ``late_rise.csv``.
COLUMNS = ("variant", "time", "mean_radius_d", "sixfold_cos")


def late_rise(radius_d, sixfold_cos, largest_d: float) -> float:
    """Mean a6/a0 beyond :data:`OUTER` of ``largest_d`` minus its mean over :data:`PLATEAU`."""
    radius_d, sixfold_cos = np.asarray(radius_d, float), np.asarray(sixfold_cos, float)

    def mean_over(low, high):
        chosen = (radius_d >= low * largest_d) & (radius_d <= high * largest_d)
        return float(np.mean(sixfold_cos[chosen])) if chosen.any() else float("nan")

    return mean_over(*OUTER) - mean_over(*PLATEAU)


def run_late_rise(study: FrontStudy, out: Path, log=None) -> dict:
    """Run the three runs, measure the four fronts; {variant: {"shape", "fit", "rise"}}."""
    config = study.configs()["uncompressed"]
    low, high = study.fit_range_d
    shapes = {}
    for name, (changes, measure) in VARIANTS.items():
        if measure == "fixed_speed":
            continue
        variant = config.replace(**changes)
        threshold = THRESHOLD_FRACTION * variant.v0 if name == "baseline" else None
        analysis = simulate(variant, out / name, log, threshold_speed=threshold)
        shapes[name] = study_front_shape(study, analysis)
        if threshold is not None:
            shapes["fixed_speed"] = study_front_shape(study, analysis, analysis.tracked.threshold_time)
    return {
        name: {
            "shape": shape,
            "fit": fit_roundness(shape.mean_radius, shape.sixfold_cos, low, high),
            "rise": late_rise(shape.mean_radius, shape.sixfold_cos, min(high, float(np.nanmax(shape.mean_radius)))),
        }
        for name, shape in ((name, shapes[name]) for name in VARIANTS)
    }


def verdict(measured: dict) -> dict:
    """What the four measurements say of the rise: ``kind`` ("no late rise", "artefact of the
    sampling", "artefact of the time step", "of the half-maximum measure", "the front's own", or
    "undetermined" where a window holds no front) and one sentence, with A∞ of each."""
    rise = {name: entry["rise"] for name, entry in measured.items()}
    base = rise["baseline"]

    def changed(name):
        return abs(rise[name] - base) > RISE_AGREEMENT * abs(base)

    fits = "; ".join(
        f"{name.replace('_', ' ')}: A∞ = {entry['fit'].a_inf:+.4f} ± {entry['fit'].a_inf_se:.4f} "
        f"(p = {entry['fit'].p:.2f}), late rise {entry['rise']:+.4f}"
        for name, entry in measured.items()
    )
    if not all(np.isfinite(list(rise.values()))):
        kind = "undetermined"
    elif not base < -2 * measured["baseline"]["fit"].a_inf_se:
        kind = "no late rise"
    elif changed("finer_sampling"):
        kind = "artefact of the sampling"
    elif changed("finer_step"):
        kind = "artefact of the time step"
    elif not rise["fixed_speed"] < -RISE_AGREEMENT * abs(base):
        kind = "of the half-maximum measure"
    else:
        kind = "the front's own"
    sentences = {
        "undetermined": "The packing is too small for fronts in both windows of the late rise: undetermined.",
        "no late rise": (
            "The anisotropy does not grow again beyond the plateau by more than twice the "
            "fit's error: there is no late rise here."
        ),
        "artefact of the sampling": "The late rise changes when the sampling is refined: it is an artefact of "
        "the sampling.",
        "artefact of the time step": "The late rise changes with the time step: it is an artefact of the "
        "discretization.",
        "of the half-maximum measure": (
            "The late rise stays under finer sampling and a finer time step, but the front "
            "of a fixed small speed does not show it: it belongs to the half-maximum measure "
            "(the pulse's shape changing with direction), not to the front's position."
        ),
        "the front's own": (
            "The late rise stays under finer sampling, a finer time step and a second measure of the "
            "front: it is physical, the front's own."
        ),
    }
    return {
        "kind": kind,
        "rises": rise,
        "verdict": f"{sentences[kind]} {fits}.",
        "fits": {name: entry["fit"].as_dict() for name, entry in measured.items()},
    }


def rows(measured: dict) -> list[tuple]:
    return [
        (name, float(t), float(r), float(a))
        for name, entry in measured.items()
        for t, r, a in zip(entry["shape"].time, entry["shape"].mean_radius, entry["shape"].sixfold_cos)
    ]


def late_rise_figure(measured: dict, path) -> None:
    """a6/a0 against the front's radius beyond the fit range's start, the four measurements
    with their fitted laws (dotted: A∞), zoomed on the late rise."""
    from hexdem.analysis import plotting as plots

    fig, ax = plots.subplots(figsize=(7, 4.8), layout="constrained")
    for k, (name, entry) in enumerate(measured.items()):
        shape, fit = entry["shape"], entry["fit"]
        keep = shape.mean_radius >= fit.radius_min_d
        ax.plot(
            shape.mean_radius[keep],
            shape.sixfold_cos[keep],
            "o",
            color=f"C{k}",
            markersize=4 - 0.6 * k,
            label=f"{name.replace('_', ' ')}: A∞ = {fit.a_inf:+.4f} ± {fit.a_inf_se:.4f}, late rise "
            f"{entry['rise']:+.4f}",
        )
        radius = np.linspace(fit.radius_min_d, fit.radius_max_d, 100)
        ax.plot(radius, fit(radius), color=f"C{k}", lw=1)
        ax.axhline(fit.a_inf, color=f"C{k}", ls=":", lw=1)
    for fraction in (*PLATEAU, OUTER[0]):
        ax.axvline(
            fraction * max(float(np.nanmax(e["shape"].mean_radius)) for e in measured.values()),
            color="grey",
            lw=0.6,
            ls="--",
        )
    ax.set_xlabel("mean front radius a₀ [d]")
    ax.set_ylabel("sixfold component a₆/a₀")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="lower left")
    ax.set_title("The late rise, measured four ways (dashed: the plateau and the outer fronts)", fontsize=10)
    plots.save(fig, path)
