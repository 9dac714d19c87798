"""The calibration's model of a measurement: the run of the base configuration with the
parameters drawn, reduced to the observables of its sensors.

Every simulation is one task of the study executor (:mod:`~hexdem.experiments.executors`) and
has a folder of its own, ``DIR/simulations/NNNN`` (``-kK`` for the K-th packing), that holds
``parameters.json`` (the values set), ``observables.json`` (the reduced record,
:func:`~hexdem.calibration.observables.reduce_record`; null where a sensor's pulse stays below what
the records' sensors detect, :func:`detected`) and the run's LAMMPS deck. It is made in
``.NNNN.part`` and renamed into place once complete, so that a folder that exists is a finished
simulation: a calibration run again (after ``kill -9``, say) finds it, checks that its
parameters are the planned ones, and does not repeat it. No figures are drawn and no result
files written: a worker loads Python and LAMMPS once and runs one impact after another.

On disordered packings (:attr:`Problem.disordered`), a simulation is packing k's preparation
(read from the cache of settled packings when another simulation has made it,
:mod:`~hexdem.calibration.packings`) and its impact under the preparation's gravity.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from hexdem.calibration.observables import at_rest_before, observation_names, reduce_record
from hexdem.calibration.packings import (
    PACKINGS,
    PAPER_SIGMA_M,
    SIGMA_KEY,
    check_disorderable,
    preparation_of,
    settled_packing,
)
from hexdem.calibration.priors import Prior
from hexdem.common.io import atomic_directory, write_json
from hexdem.common.progress import silenced
from hexdem.common.typecheck import type_at
from hexdem.errors import HexdemError
from hexdem.experiments.sweep_plan import with_value
from hexdem.model.config import RunConfig
from hexdem.model.model_builder import build_model
from hexdem.model.run_settings import run_settings

SIMULATIONS = "simulations"
#: Values inside a prior's support at which every configuration is built before anything runs.
CHECKED_QUANTILES = (0.0, 0.5, 1.0)


@dataclass(frozen=True)
class Problem:
    """What a calibration simulates: the base configuration table ``base``, the ``priors`` of
    the parameters it draws, the ``realizations`` (packings) per parameter set, the
    ``seed`` of the packings' diameters, the ``axes`` each sensor measured (x, y), with which
    a simulation's record is reduced as the measured ones are (None: both), and each sensor's
    smallest detectable peak acceleration ``detection_m_s2`` [m/s²] (None: every pulse is detected),
    below which a simulation's packing holds no pulse that the records' sensors would detect."""

    base: dict
    priors: tuple[Prior, ...]
    realizations: int = 1
    seed: int = 0
    axes: tuple[tuple[bool, bool], ...] | None = None
    detection_m_s2: tuple[float, ...] | None = None

    @property
    def keys(self) -> list[str]:
        return [prior.key for prior in self.priors]

    @property
    def disordered(self) -> bool:
        """Whether each parameter set is simulated on disordered packings: σ is calibrated, or
        there are several packings."""
        return SIGMA_KEY in self.keys or self.realizations > 1

    def sigma_m(self, values) -> float:
        """σ of the diameters of the parameter set ``values`` [m] (the paper's, if not calibrated)."""
        return float(values[self.keys.index(SIGMA_KEY)]) if SIGMA_KEY in self.keys else PAPER_SIGMA_M

    def config(self, values) -> RunConfig:
        """The run configuration with the parameters ``values`` (in the priors' order) set."""
        data = self.base
        for prior, value in zip(self.priors, values):
            if prior.key == SIGMA_KEY:
                continue
            kind = type_at(RunConfig, prior.key)
            data = with_value(data, prior.key, int(round(value)) if kind is int else float(value), option="--prior")
        return RunConfig.from_dict(data, source="the calibrated configuration")

    @property
    def sensors(self) -> list[str]:
        return [str(sensor) for sensor in RunConfig.from_dict(self.base, source="--config").sensors]

    @property
    def names(self) -> list[str]:
        return observation_names(self.sensors)


def check_problem(problem: Problem) -> None:
    """Refuse, in one line and before anything runs, a base configuration without sensors, a
    prior on a key that is not a number of the configuration, and a prior whose support leaves
    the key's valid range (each configuration is built at the support's ends and middle)."""
    base = RunConfig.from_dict(problem.base, source="--config")
    if not base.sensors:
        raise HexdemError(
            "--config: a calibration compares sensor records; list the measured sensors in the configuration's sensors"
        )
    if base.engine != "lammps" or base.ranks != 1:
        raise HexdemError(
            "--config: a calibration runs each simulation on one LAMMPS rank of its own (--workers "
            "runs several at once); leave engine and ranks at their defaults"
        )
    for prior in problem.priors:
        if prior.key == SIGMA_KEY:
            if prior.support[0] < 0:
                raise HexdemError(
                    f"--prior {SIGMA_KEY}: the standard deviation of the diameters must be >= 0 m, "
                    f"but {prior.describe()} reaches {prior.support[0]:.6g} m"
                )
            continue
        kind = type_at(RunConfig, prior.key)
        if kind is None or kind is bool or not any(t in (int, float) for t in (kind, *getattr(kind, "__args__", ()))):
            raise HexdemError(f"--prior {prior.key}: not a numeric key of the run configuration")
        if kind is int and prior.kind != "uniform":
            raise HexdemError(f"--prior {prior.key}: an integer key takes uniform(a, b)")
    for quantile in CHECKED_QUANTILES:
        values = [float(prior.from_unit(min(max(quantile, 1e-9), 1 - 1e-9))) for prior in problem.priors]
        try:
            config = problem.config(values)
            run_settings(config, build_model(config))
        except HexdemError as exc:
            named = ", ".join(f"{prior.key} = {value:.6g}" for prior, value in zip(problem.priors, values))
            raise HexdemError(
                f"--prior: the configuration with {named} (inside the priors) is refused: {exc}"
            ) from None
    if problem.disordered:
        largest = max((prior.support[1] for prior in problem.priors if prior.key == SIGMA_KEY), default=PAPER_SIGMA_M)
        check_disorderable(base, largest, problem.realizations, problem.seed)


def simulation_name(index: int, realization: int, realizations: int) -> str:
    return f"{index:04d}" if realizations == 1 else f"{index:04d}-k{realization}"


def finished(folder: Path, values) -> np.ndarray | None:
    """The observables of the finished simulation in ``folder``, or None if it has not run; a
    folder that holds other parameters is refused (the study folder holds another calibration)."""
    path = folder / "observables.json"
    if not path.is_file():
        return None
    stored = json.loads((folder / "parameters.json").read_text())["values"]
    if not np.allclose(stored, values, rtol=1e-12, atol=0.0):
        raise HexdemError(
            f"{folder} holds a simulation of other parameters: {folder.parent.parent} holds another "
            "calibration; rerun the same command to resume it, or choose another --out"
        )
    return np.array(json.loads(path.read_text())["observables"], dtype=float)


def detected(problem: Problem, accelerations) -> bool:
    """Whether every sensor's peak acceleration (``accelerations`` (n_sensors, K, 2) [m/s²], over the
    axes measured) reaches its :attr:`Problem.detection_m_s2`: a packing that does not is a record
    the lab would have left out (no pulse at a sensor), and its observables are NaN."""
    if problem.detection_m_s2 is None:
        return True
    axes = np.ones((len(accelerations), 2), bool) if problem.axes is None else np.asarray(problem.axes, bool)
    peaks = np.max(np.sqrt(np.sum((accelerations * axes[:, None, :]) ** 2, axis=2)), axis=1)
    return bool(np.all(peaks >= np.asarray(problem.detection_m_s2)))


def disordered_impact(config: RunConfig, sigma_m: float, seed: int, realization: int, workdir, packings):
    """The analysed impact of ``config`` on its packing ``realization`` at σ = ``sigma_m`` from
    ``seed`` (:func:`~hexdem.calibration.packings.settled_packing`, cached in ``packings``),
    under the gravity it settled in."""
    from hexdem.experiments.run import check_energy
    from hexdem.experiments.tracked_run import ImpactJob, track_impact

    nominal = build_model(config)
    packing, gravity = settled_packing(nominal, preparation_of(config), sigma_m, seed, realization, packings)
    model = replace(nominal, packing=packing)
    job = ImpactJob(
        model,
        run_settings(config, nominal),
        "lammps",
        Path(workdir),
        gravity_m_s2=tuple(float(g) for g in gravity),
        show_progress=False,
    )
    analysis = track_impact(job)
    check_energy(analysis, workdir)
    return analysis


def analysed_impact(problem: Problem, values, realization: int, workdir: Path, packings: Path):
    """The analysed impact of the parameter set ``values``: on the ideal lattice, or on its
    packing ``realization``."""
    from hexdem.experiments.run import simulate

    config = problem.config(values)
    if not problem.disordered:
        return simulate(config, workdir)
    return disordered_impact(config, problem.sigma_m(values), problem.seed, realization, workdir, packings)


def simulate_point(problem: Problem, values, folder, realization: int = 0) -> list[float]:
    """Run the parameter set ``values`` (on packing ``realization`` when disordered) in ``folder``
    (made via a ``.part`` folder; the packings cached beside the study's ``simulations``) and
    return its observables; a task of the study executor."""
    folder = Path(folder)
    if (done := finished(folder, values)) is not None:
        return done.tolist()
    with atomic_directory(folder) as partial:
        partial.mkdir(parents=True)
        write_json(partial / "parameters.json", {"keys": problem.keys, "values": [float(v) for v in values]})
        with silenced():
            analysis = analysed_impact(problem, values, realization, partial / "deck", folder.parent.parent / PACKINGS)
        units, tracked = analysis.settings.units, analysis.tracked
        times = tracked.sensor_times * units.time_s
        accelerations = np.moveaxis(tracked.sensor_states[:, :, 2:4], 1, 0) * (units.length_m / units.time_s**2)
        observables = (
            reduce_record(*at_rest_before(times, accelerations), problem.axes)
            if detected(problem, accelerations)
            else np.full(len(problem.names), np.nan)
        )
        write_json(
            partial / "observables.json",
            {
                "names": problem.names,
                "observables": observables.tolist(),
                "engine_wall_time_s": analysis.engine.get("wall_time_s", math.nan),
            },
        )
    return observables.tolist()
