r"""What Mindlin friction and rotation do to the paper's results: the study of ``hexdem paper``.

**Set-up.** The disorder study's (:mod:`hexdem.paper.disorder_study`): the experiment's
11-per-edge hexagon (the quick run's smaller) struck by the steel striker at 0.25, 0.40 and
0.70 m/s, as the ideal lattice (σ = 0) and as packings prepared with σ = 6 tol. For each Coulomb
μ of :data:`~hexdem.paper.settings.FRICTIONS` (the quick run's fewer), the ensemble
``friction/friction<μ>`` is the paper's σ = 6 tol ensemble with ``friction = μ``
(:class:`~hexdem.disorder.ensemble.EnsembleConfig`), on its first
:attr:`~hexdem.paper.settings.PaperSettings.friction_realizations` packings. It adopts the
frictionless ensemble's preparation (:mod:`hexdem.disorder.sharing`), so the very same packings
are struck with and without friction.

**Measured against μ = 0, on the same packing at the same speed** (``friction_effect.csv``):
``mean_peak_ratio`` is the leading pulse's amplitude (:mod:`hexdem.analysis.leading_pulse`)
V_n(μ) / V_n(0), averaged over the beads n ≥ 2 of the line (``±30`` pools both 30° lines), per
packing, then over packings; ``sem_peak_ratio`` its standard error over packings (NaN for
the ideal lattice: one run, exact, LAMMPS being deterministic on one rank);
``mean_arrival_shift_us`` is t_n(μ) − t_n(0) averaged the same way [µs] (negative: earlier).

**Decay rates** (``friction_decay.csv``): Sec. V's c of :math:`V_n = V_s c^{n − s}`
(:func:`~hexdem.theory.scaling.fit_decay`, the anchored log-linear fit) on the ideal lattice's
leading pulses, for the 0° strike observed along 0° (``0/0``, s = 2) and along +30° (``0/30``,
s = 1), up to the last bead of the line that no wall touches.

**Disorder with friction.** The paper's claim (Sec. VI-B) is that at σ = 6 tol transmission
along ±30° rises above the ideal lattice's while 0° falls. Each frictional ensemble measures
its disordered / ideal transmission with friction in both, at the study's 0.40 m/s, and
:func:`~hexdem.paper.disorder_study.change` reads it at two standard errors.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from hexdem.disorder.ensemble import Ensemble, EnsembleConfig
from hexdem.disorder.runner import run_ensemble
from hexdem.disorder.stats import EFFECT_COLUMNS as ENSEMBLE_EFFECT_COLUMNS
from hexdem.disorder.stats import EFFECT_FIRST_N, disorder_effect, load_results, mean_and_sem
from hexdem.errors import HexdemError
from hexdem.paper.disorder_study import FIGURES_ENSEMBLE, MEASURES, StudyEnsemble, change, json_number
from hexdem.paper.settings import FIG9_VELOCITIES_M_S, STUDY_VELOCITY_M_S, PaperSettings
from hexdem.theory.scaling import fit_decay

#: σ / tol of the study's disordered packings: the paper's.
FRICTION_SIGMA_PER_TOL = 6.0
#: Columns of ``friction_effect.csv`` (a contract).
EFFECT_COLUMNS = (
    "friction",
    "v_striker",
    "sigma_tol",
    "line",
    "mean_peak_ratio",
    "sem_peak_ratio",
    "mean_arrival_shift_us",
)
#: Columns of ``friction_decay.csv``.
DECAY_COLUMNS = ("friction", "v_striker", "combination", "decay_rate", "decay_rate_stderr", "ratio_to_frictionless")
#: Sec. V's combinations on the experiment's 0° strike: (name, line, start bead s).
COMBINATIONS = (("0/0", "0", 2), ("0/30", "+30", 1))
#: Lines of the study.
LINES = ("0", "±30")


def friction_name(mu: float) -> str:
    """The directory and part name of the ensemble with friction ``mu``."""
    return f"friction{mu:g}"


def _paper_config(settings: PaperSettings) -> EnsembleConfig:
    return StudyEnsemble(FRICTION_SIGMA_PER_TOL, False, FIG9_VELOCITIES_M_S).config(settings)


def friction_config(mu: float, settings: PaperSettings) -> EnsembleConfig:
    """The σ = 6 tol ensemble with friction ``mu`` on the study's packings (μ = 0: the paper's
    own ensemble, cut to the same packings)."""
    return replace(_paper_config(settings), friction=mu, realizations=settings.friction_realizations)


def run_friction_ensemble(mu: float, settings: PaperSettings, parsl, out: Path, scaling_json) -> dict:
    """Run (or resume) the ensemble with friction ``mu`` into ``out / friction / <name>`` (on
    ``parsl``, the paper's :class:`~hexdem.experiments.executors.ParslSession`, or None),
    adopting the paper's σ = 6 tol preparation from ``out / disorder``; its summary."""
    paper = Ensemble(_paper_config(settings), out / "disorder" / FIGURES_ENSEMBLE)
    if not paper.out.is_dir():
        raise HexdemError(f"{paper.out} is missing: the friction study strikes that ensemble's packings")
    summary = run_ensemble(
        friction_config(mu, settings),
        out / "friction" / friction_name(mu),
        workers=settings.workers,
        launcher=settings.launcher,
        parsl=parsl,
        scaling_json=scaling_json,
        log=lambda message: None,
        share_from=(paper,),
    )
    return {
        "name": friction_name(mu),
        "friction": mu,
        **{key: summary[key] for key in ("this_run", *MEASURES.values())},
    }


def _line_beads(lattice) -> dict[str, np.ndarray]:
    """The beads n ≥ 2 of the study's lines; ``±30`` pools both 30° lines."""
    lines = {name: beads[EFFECT_FIRST_N:] for name, beads in lattice.lines().items()}
    return {"0": lines["0"], "±30": np.concatenate([lines["+30"], lines["-30"]])}


def effect_rows(results: dict, lattice) -> list[tuple]:
    """Rows of ``friction_effect.csv`` from {μ: EnsembleResults} (μ = 0 included) of ``lattice``."""
    base = results[0.0]
    rows = []
    for mu, r in results.items():
        for iv, v in enumerate(r.velocities_m_s):
            for line, beads in _line_beads(lattice).items():
                with np.errstate(invalid="ignore", divide="ignore"):
                    ideal_ratio = r.ideal_lead_speed[iv, beads] / base.ideal_lead_speed[iv, beads]
                    ratio = r.lead_speed[:, iv, beads] / base.lead_speed[:, iv, beads]
                ideal_shift = (r.ideal_arrival_time[iv, beads] - base.ideal_arrival_time[iv, beads]) * 1e6
                shift = (r.arrival_time[:, iv, beads] - base.arrival_time[:, iv, beads]) * 1e6
                rows.append(
                    (
                        mu,
                        float(v),
                        0.0,
                        line,
                        float(np.nanmean(ideal_ratio)),
                        float("nan"),
                        float(np.nanmean(ideal_shift)),
                    )
                )
                mean, sem = mean_and_sem(np.nanmean(ratio, axis=1))
                rows.append(
                    (mu, float(v), FRICTION_SIGMA_PER_TOL, line, mean, sem, mean_and_sem(np.nanmean(shift, axis=1))[0])
                )
    return rows


def _last_free_bead(beads: np.ndarray, walls) -> int:
    """The last n of a line whose bead no wall touches."""
    walled = set(np.concatenate([np.asarray(w.members) for w in walls]).tolist())
    return max(n for n, bead in enumerate(beads) if int(bead) not in walled)


def decay_rows(results: dict, lattice) -> list[tuple]:
    """Rows of ``friction_decay.csv``: Sec. V's decay rate on the ideal lattice's leading pulses
    (NaN where a bead of the window had no leading pulse)."""
    lines = lattice.lines()
    rates = {}
    for mu, r in results.items():
        for iv, v in enumerate(r.velocities_m_s):
            for name, line, start in COMBINATIONS:
                beads = lines[line]
                try:
                    rates[mu, float(v), name] = fit_decay(
                        np.arange(len(beads)),
                        r.ideal_lead_speed[iv, beads],
                        start,
                        _last_free_bead(beads, lattice.walls),
                    )
                except HexdemError:
                    rates[mu, float(v), name] = (float("nan"), float("nan"))
    return [(mu, v, name, c, err, c / rates[0.0, v, name][0]) for (mu, v, name), (c, err) in rates.items()]


def disorder_conditions(summaries: dict) -> list[dict]:
    """At every μ (summaries {μ: summary with the ensemble's effects}) and both measures, what
    σ = 6 tol does to ±30° and 0° at the study's speed, friction in the ideal lattice too."""
    conditions = []
    for mu, summary in sorted(summaries.items()):
        for measure, key in MEASURES.items():
            at = {e["line"]: e for e in summary[key] if np.isclose(e["v_striker"], STUDY_VELOCITY_M_S)}
            pm30, zero = at["±30"], at["0"]
            conditions.append(
                {
                    "friction": mu,
                    "measure": measure,
                    "realizations": pm30["realizations"],
                    "pm30": change(
                        json_number(pm30["mean_ratio"]), json_number(pm30["sem_ratio"]), pm30["realizations"]
                    ),
                    "pm30_ratio": json_number(pm30["mean_ratio"]),
                    "pm30_sem": json_number(pm30["sem_ratio"]),
                    "zero": change(
                        json_number(zero["mean_ratio"]), json_number(zero["sem_ratio"]), zero["realizations"]
                    ),
                    "zero_ratio": json_number(zero["mean_ratio"]),
                    "zero_sem": json_number(zero["sem_ratio"]),
                }
            )
    return conditions


def _study_rows(rows: list[tuple], sigma_tol: float) -> dict:
    """{(μ, line): row} of the frictional rows at the study's speed and ``sigma_tol``."""
    return {(r[0], r[3]): r for r in rows if r[0] > 0 and r[2] == sigma_tol and np.isclose(r[1], STUDY_VELOCITY_M_S)}


def arrival_verdict(rows: list[tuple]) -> str:
    """Does friction lengthen the arrivals, as the experiment's longer ones would need? One
    sentence from the ideal lattice's rows at the study's speed."""
    at = _study_rows(rows, 0.0)
    listed = "; ".join(
        f"μ = {mu:g}: 0° {at[mu, '0'][6]:+.2f} µs, ±30° {at[mu, '±30'][6]:+.2f} µs"
        for mu in sorted({mu for mu, _ in at})
    )
    amplitude = ", ".join(
        f"{line}° {100 * min(at[k][4] for k in at if k[1] == line):.0f}–"
        f"{100 * max(at[k][4] for k in at if k[1] == line):.0f} %"
        for line in LINES
    )
    delayed = [line for line in LINES if all(at[k][6] > 0 for k in at if k[1] == line)]
    advanced = [line for line in LINES if all(at[k][6] < 0 for k in at if k[1] == line)]
    if len(delayed) == len(LINES):
        finding = (
            "friction delays the leading pulse, in the direction of the experiment's longer arrival times (Sec. VI)"
        )
    elif len(advanced) == len(LINES):
        finding = (
            "friction brings the leading pulse forward (the tangential stiffness stiffens the contacts), "
            "so it cannot explain the experiment's longer arrival times (Sec. VI)"
        )
    elif delayed and advanced:
        finding = (
            f"friction delays the arrivals along {' and '.join(d + '°' for d in delayed)} but brings them "
            f"forward along {' and '.join(a + '°' for a in advanced)}: it lengthens the arrivals, as the "
            f"experiment's longer ones (Sec. VI) would need, only along {' and '.join(d + '°' for d in delayed)}"
        )
    else:
        finding = "friction moves the arrivals both ways, so it alone does not explain the experiment's longer ones"
    return (
        f"In the ideal lattice at {STUDY_VELOCITY_M_S:.2f} m/s the mean arrival shift over the beads n ≥ 2 is "
        f"{listed}: {finding}. The leading pulse keeps {amplitude} of its frictionless amplitude."
    )


def disorder_verdict(conditions: list[dict]) -> str:
    """Does ±30° rise while 0° falls at σ = 6 tol once the beads rub? One sentence."""

    def listed(chosen):
        return "; ".join(f"μ = {c['friction']:g} ({c['measure']})" for c in chosen)

    frictional = [c for c in conditions if c["friction"] > 0]
    claim = [c for c in frictional if c["pm30"] == "rises" and c["zero"] == "falls"]
    rises = [c for c in frictional if c["pm30"] == "rises"]
    details = "; ".join(
        f"μ = {c['friction']:g} ({c['measure']}, {c['realizations']} packings): ±30° {c['pm30']} "
        f"({c['pm30_ratio']:.3f} ± "
        f"{c['pm30_sem']:.3f}), 0° {c['zero']} ({c['zero_ratio']:.3f} ± {c['zero_sem']:.3f})"
        for c in conditions
    )
    if claim:
        head = f"With friction, ±30° rises while 0° falls at σ = 6 tol, as the paper says, for {listed(claim)}"
    elif rises:
        head = f"With friction, ±30° rises at σ = 6 tol for {listed(rises)}, but 0° does not fall there"
    else:
        head = (
            "With friction, transmission along ±30° does not rise above the frictional ideal lattice's at "
            "σ = 6 tol for any μ studied: friction does not restore the paper's claim"
        )
    return f"{head}. Disordered / ideal, both with the same μ, at {STUDY_VELOCITY_M_S:.2f} m/s: {details}."


def friction_tables(out: Path, settings: PaperSettings, summaries: dict) -> tuple[list, list, list]:
    """(rows of ``friction_effect.csv``, rows of ``friction_decay.csv``, disorder conditions) of
    the finished ensembles in ``out``; ``summaries`` {μ: summary} of the frictional ensembles.
    μ = 0's disorder condition is measured on the same packings as theirs, the paper's first."""
    ensembles = {0.0: Ensemble(friction_config(0.0, settings), out / "disorder" / FIGURES_ENSEMBLE)}
    ensembles |= {
        mu: Ensemble(friction_config(mu, settings), out / "friction" / friction_name(mu)) for mu in settings.frictions
    }
    results = {mu: load_results(ensemble) for mu, ensemble in ensembles.items()}
    lattice = ensembles[0.0].ideal
    frictionless = {
        key: [dict(zip(ENSEMBLE_EFFECT_COLUMNS, row)) for row in disorder_effect(results[0.0], lattice, measure)]
        for measure, key in MEASURES.items()
    }
    return (
        effect_rows(results, lattice),
        decay_rows(results, lattice),
        disorder_conditions({0.0: frictionless, **summaries}),
    )
