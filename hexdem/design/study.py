"""``hexdem design``: the sensors and the striker speed whose records tell the keys best.

Every parameter set of a space-filling design over the priors is simulated once per striker speed
(and per packing, where the packings are disordered), every candidate bead recorded
(:mod:`~hexdem.design.records`); the criterion (:mod:`~hexdem.design.criterion`) scores a set of
sensors from those simulations alone, so that the search (:mod:`~hexdem.design.search`) scores
thousands of sets for the price of the simulations. Writes ``design.csv`` (the best designs,
ranked), ``design.json`` and ``design.png``. A study is resumable: a simulation's folder exists
only once finished, and the same command finds it.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hexdem.calibration import inference
from hexdem.calibration.packings import SIGMA_KEY, on_sigma_levels
from hexdem.calibration.priors import parse_priors, to_parameters
from hexdem.calibration.simulations import Problem, check_problem
from hexdem.calibration.study import instrument_sd, realizations_of
from hexdem.common.checks import positive_int
from hexdem.common.io import ensure_writable_dir, keep_plan, locked_directory, write_csv, write_json
from hexdem.design.candidates import PAPER_CONFIGURATIONS, candidate_labels, is_paper_lattice, sensor_value
from hexdem.design.criterion import Moments, bootstrapped
from hexdem.design.records import finished_moments, simulate_beads
from hexdem.design.search import search
from hexdem.errors import HexdemError
from hexdem.experiments.executors import check_study_options, holding, parsl_session, run_phase
from hexdem.model.config import RunConfig

PLAN_NAME = "design-plan.json"
SIMULATIONS = "simulations"
#: Designs written to ``design.csv``.
RANKED = 20
#: Parameter sets per striker speed by default: this many per key, plus as many again.
SETS_PER_KEY = 10
#: The noise is bootstrapped on every this many parameter sets (on their first packing).
NOISE_EVERY = 3


@dataclass(frozen=True)
class DesignStudy:
    """A checked design study: the simulations' ``problems`` (one per speed, every recorded bead a
    sensor), the ``candidates`` and the beads ``recorded`` (the candidates and the paper's
    configurations' beads), ``sensors`` N per design, ``records`` R per design, the instruments
    (``noise_m_s2``, ``gain_sd``, ``speed_scatter``), ``sets`` parameter sets per speed, ``seed``."""

    problems: dict[float, Problem]
    candidates: tuple[str, ...]
    recorded: tuple[str, ...]
    sensors: int
    records: int
    noise_m_s2: float
    gain_sd: float
    speed_scatter: float
    sets: int
    seed: int
    paper: bool

    @property
    def priors(self):
        return next(iter(self.problems.values())).priors

    @property
    def realizations(self) -> int:
        return next(iter(self.problems.values())).realizations


def _speeds(text, base: RunConfig, priors) -> tuple[float, ...]:
    if text is None:
        return (float(base.v0),)
    if any(prior.key == "v0" for prior in priors):
        raise HexdemError("--speeds: v0 has a prior; design over the speeds or calibrate v0, not both")
    try:
        speeds = tuple(float(word) for word in str(text).split(","))
    except ValueError:
        raise HexdemError(f"--speeds {text!r}: striker speeds separated by commas, e.g. 0.25,0.40,0.70") from None
    bad = [v for v in speeds if not (np.isfinite(v) and v > 0)]
    if bad or len(set(speeds)) != len(speeds):
        raise HexdemError(f"--speeds {text!r}: distinct striker speeds > 0 (got {bad[0] if bad else 'one twice'})")
    return speeds


def prepare_design(
    base: dict,
    prior_texts,
    sensors: int,
    candidates: str,
    speeds,
    records: int,
    noise_m_s2: float,
    gain_sd: float,
    speed_scatter: float,
    realizations: int | None,
    budget: int | None,
    seed: int,
) -> DesignStudy:
    """Every check of the input, each a line, before anything is written or run."""
    priors = parse_priors(prior_texts)
    realizations = realizations_of(priors, realizations)
    sensors, records = positive_int("--sensors", sensors), positive_int("--records", records)
    if not (isinstance(noise_m_s2, (int, float)) and np.isfinite(noise_m_s2) and noise_m_s2 > 0):
        raise HexdemError(f"--noise {noise_m_s2!r}: the accelerometers' noise, rms in m/s² per channel, > 0")
    gain_sd, speed_scatter = instrument_sd("--sensor-gain-sd", gain_sd), instrument_sd("--speed-scatter", speed_scatter)
    config = RunConfig.from_dict({key: value for key, value in base.items() if key != "sensors"}, source="--config")
    labels = candidate_labels(config, candidates)
    if sensors > len(labels):
        raise HexdemError(f"--sensors {sensors}: there are only {len(labels)} candidate beads")
    paper = is_paper_lattice(config)
    recorded = list(labels)
    if paper:
        recorded += [s for c in PAPER_CONFIGURATIONS.values() for s in c if s not in recorded]
    recorded = list(dict.fromkeys(recorded))
    problems = {}
    for v in _speeds(speeds, config, priors):
        table = base | {"sensors": [sensor_value(s) for s in recorded], "sensor_mass_factor": 1.0, "v0": v}
        problems[v] = Problem(table, tuple(priors), realizations, seed)
        check_problem(problems[v])
    smallest = (len(priors) + 1) * (len(priors) + 2) // 2 + 4
    sets = SETS_PER_KEY * (len(priors) + 1)
    if budget is not None:
        sets = positive_int("--budget", budget) // (len(problems) * realizations)
        if sets < smallest:
            raise HexdemError(
                f"--budget {budget}: at least {smallest * len(problems) * realizations} simulations "
                f"({smallest} parameter sets a speed, for an emulator of {len(priors)} key(s), x "
                f"{len(problems)} speed(s) x {realizations} packing(s))"
            )
    return DesignStudy(
        problems,
        tuple(labels),
        tuple(recorded),
        sensors,
        records,
        float(noise_m_s2),
        gain_sd,
        speed_scatter,
        sets,
        int(seed),
        paper,
    )


def _plan(study: DesignStudy) -> dict:
    first = next(iter(study.problems.values()))
    return {
        "base": {key: value for key, value in first.base.items() if key not in ("sensors", "v0")},
        "priors": [prior.describe() for prior in study.priors],
        "speeds": list(study.problems),
        "recorded": list(study.recorded),
        "realizations": study.realizations,
        "sets": study.sets,
        "noise_m_s2": study.noise_m_s2,
        "seed": study.seed,
    }


def _simulate(study: DesignStudy, out: Path, workers: int, parsl) -> tuple[dict, int]:
    """Run every simulation not finished before; {speed: (values (M, p), observables (M, K, n, 2),
    noise (M, n, 3) of each set's first packing, NaN where not bootstrapped)} of the parameter sets
    whose every packing ran, and the failed count."""
    unit = inference.design(len(study.priors), study.sets, study.seed)
    keys = [prior.key for prior in study.priors]
    if SIGMA_KEY in keys:  # parameter sets share their packings, as a calibration's do
        unit = on_sigma_levels(unit, keys.index(SIGMA_KEY))
    values = to_parameters(study.priors, unit)
    folders = {
        (v, i, k): out / SIMULATIONS / f"v{v:.4g}-{i:04d}-k{k}"
        for v in study.problems
        for i in range(study.sets)
        for k in range(study.realizations)
    }
    tasks = {
        key: (
            simulate_beads,
            study.problems[key[0]],
            values[key[1]].tolist(),
            str(folder),
            study.noise_m_s2,
            study.seed,
            key[2],
            key[2] == 0 and key[1] % NOISE_EVERY == 0,
        )
        for key, folder in folders.items()
        if finished_moments(folder, values[key[1]]) is None
    }
    failed = {
        key
        for key, error in run_phase(tasks, workers, parsl, "design", "simulation", len(folders) - len(tasks))
        if error
    }
    results = {}
    for v in study.problems:
        kept = [i for i in range(study.sets) if not any((v, i, k) in failed for k in range(study.realizations))]
        arrays = [[finished_moments(folders[(v, i, k)], values[i]) for k in range(study.realizations)] for i in kept]
        results[v] = (
            values[kept],
            np.array([[a["observables"] for a in row] for row in arrays]),
            np.array([row[0]["noise"] for row in arrays]),
        )
    return results, len(failed)


def _row(moments: Moments, recorded, beads, v: float, study: DesignStudy) -> dict:
    criterion, widths = moments.score(list(beads), study.records, study.gain_sd, study.speed_scatter)
    order, _ = moments.design_map(list(beads))
    return {
        "sensors": " ".join(recorded[b] for b in order),
        "v_striker": v,
        "criterion": criterion,
        **{f"width_{prior.key}": float(w) for prior, w in zip(study.priors, widths)},
    }


def _configuration(name: str, row: dict | None, priors) -> dict | None:
    """A paper configuration's entry of ``design.json`` from its scored ``row`` (None: a bead of it
    saw no pulse)."""
    if row is None:
        return None
    return {
        "sensors": list(PAPER_CONFIGURATIONS[name]),
        "v_striker": row["v_striker"],
        "criterion": row["criterion"],
        "widths": {prior.key: row[f"width_{prior.key}"] for prior in priors},
    }


def run_design(study: DesignStudy, out, workers: int = 1, parsl=None, log=print) -> dict:
    """Run ``study`` into ``out``; the summary written to ``design.json``."""
    from hexdem.design.figure import design_figure

    check_study_options(workers)
    parsl = parsl_session(parsl)
    out = ensure_writable_dir(out)
    started = time.perf_counter()
    with locked_directory(out, "another hexdem design"), holding(parsl, workers):
        keep_plan(out / PLAN_NAME, _plan(study), "design")
        log(
            f"{study.sets} parameter set(s) x {len(study.problems)} speed(s) x {study.realizations} packing(s), "
            f"{len(study.recorded)} beads recorded in each"
        )
        results, failed = _simulate(study, out, workers, parsl)
        rows, methods, dropped = [], {}, set()
        paper_rows = {}
        for v, (values, observables, noise) in results.items():
            if len(values) < (len(study.priors) + 1) * (len(study.priors) + 2) // 2:
                raise HexdemError(f"{failed} simulations failed (see {out / SIMULATIONS}); too few are left")
            usable = np.all(np.isfinite(observables), axis=(0, 1, 3)) & np.all(
                np.isfinite(noise[bootstrapped(noise)]), axis=(0, 2)
            )
            dropped |= {study.recorded[b] for b in np.flatnonzero(~usable) if study.recorded[b] in study.candidates}
            pool = [b for b, label in enumerate(study.recorded) if label in study.candidates and usable[b]]
            if len(pool) < study.sensors:
                raise HexdemError(
                    f"only {len(pool)} candidate beads see the pulse in every simulation at {v:g}; "
                    f"--sensors {study.sensors} needs more"
                )
            moments = Moments.of([p.key for p in study.priors], values, observables, noise, study.priors)
            methods[v], scored = search(
                lambda design, pool=pool, moments=moments: moments.score(
                    [pool[c] for c in design], study.records, study.gain_sd, study.speed_scatter
                )[0],
                len(pool),
                study.sensors,
            )
            best = sorted(scored, key=scored.get, reverse=True)[:RANKED]
            rows += [_row(moments, study.recorded, [pool[c] for c in design], v, study) for design in best]
            if study.paper:
                index = {label: b for b, label in enumerate(study.recorded)}
                paper_rows[v] = {
                    name: _row(moments, study.recorded, [index[s] for s in sensors], v, study)
                    if all(usable[index[s]] for s in sensors)
                    else None
                    for name, sensors in PAPER_CONFIGURATIONS.items()
                }
        rows = sorted(rows, key=lambda row: -row["criterion"])[:RANKED]
        keys = [f"width_{prior.key}" for prior in study.priors]
        write_csv(
            out / "design.csv",
            ("rank", "sensors", "v_striker", "criterion", *keys),
            [
                (rank, r["sensors"], r["v_striker"], r["criterion"], *(r[k] for k in keys))
                for rank, r in enumerate(rows, 1)
            ],
        )
        best = rows[0]
        summary = {
            "method": {
                "criterion": "expected information gain [nats] about the keys, standardised by their priors: the mean "
                "over the simulated parameter sets of -1/2 log det of the linearised posterior covariance, under the "
                "likelihood of hexdem calibrate (noise per bead, gains, speed scatter, packings' spread; R records)",
                "search": {f"{v:g}": method for v, method in methods.items()},
                "widths": "expected central 90 % widths, 2 x 1.645 sqrt of the posterior variance, at most the prior's",
                "sensor_mass": "candidates simulated as plain beads (sensor_mass_factor 1)",
                "not_foreseen": "a posterior far from Gaussian; the model discrepancy a calibration would find",
            },
            "simulations": {
                "runs": len(study.problems) * study.sets * study.realizations,
                "failed": failed,
                "parameter_sets_per_speed": study.sets,
                "realizations": study.realizations,
                "seconds": time.perf_counter() - started,
            },
            "best": best,
            "candidates": len(study.candidates),
            "candidates_without_pulse": sorted(dropped),
            "records": study.records,
            "noise_m_s2": study.noise_m_s2,
            "sensor_gain_sd": study.gain_sd,
            "speed_scatter": study.speed_scatter,
            "priors": [prior.describe() for prior in study.priors],
        }
        if study.paper:
            scored = {
                v: {name: _configuration(name, row, study.priors) for name, row in rows_at.items()}
                for v, rows_at in paper_rows.items()
            }
            summary["paper_configurations"] = scored[best["v_striker"]]
            summary["paper_configurations_by_speed"] = {f"{v:g}": entry for v, entry in scored.items()}
        write_json(out / "design.json", summary)
        design_figure(
            next(iter(study.problems.values())),
            best,
            summary.get("paper_configurations"),
            study.priors,
            study.records,
            out / "design.png",
        )
    if dropped:
        log(f"note: {len(dropped)} candidate bead(s) saw no pulse in some simulation and were left out")
    return summary
