"""hexdem's Python API: the few names a script or a notebook needs (``import hexdem``).

* :class:`RunConfig` — one impact simulation (the paper's experiment by default);
* :func:`simulate_impact` — run it and get arrays back (peak speed, time of peak and arrival
  time along each observation line, energy drift), writing files only if asked;
* :func:`tca` — ω and c of the ternary collision approximation (Sec. IV);
* :class:`SweepSettings` and :func:`scaling_laws` — the V₀ sweep of Sec. V and the fitted
  laws (9), (10), (11) of the four strike/observation combinations.
"""

from __future__ import annotations

import sys
import tempfile
from dataclasses import dataclass

import numpy as np

from hexdem.analysis.impact import ImpactAnalysis
from hexdem.experiments.run import run_experiment, simulate
from hexdem.model.config import RunConfig
from hexdem.model.unused_keys import check_unused_keys
from hexdem.theory import tca as _tca
from hexdem.theory.scaling import COMBINATIONS, CombinationFit
from hexdem.theory.sweep import SweepSettings, run_sweep

__all__ = ["RunConfig", "ImpactResult", "LineResult", "simulate_impact", "tca", "SweepSettings", "scaling_laws"]


@dataclass(frozen=True)
class LineResult:
    """One observation line, bead n = 0 (the struck bead) first, in the run's units:
    ``bead_id`` (1-based, as in the decks), ``peak_speed``, ``t_peak``, ``arrival_time``."""

    bead_id: np.ndarray
    peak_speed: np.ndarray
    t_peak: np.ndarray
    arrival_time: np.ndarray


@dataclass(frozen=True)
class ImpactResult:
    """What :func:`simulate_impact` returns, in the run's ``units`` ("si" or "nondimensional").

    ``lines``: {"0", "+30", "-30"} → :class:`LineResult`; per bead (N,): ``positions`` (N, 2),
    ``peak_speed``, ``t_peak``, ``arrival_time``; ``energy_drift`` max |E − E0|/E0;
    ``far_wall_reached``: the leading wave passed the wall facing the strike.
    """

    units: str
    lines: dict[str, LineResult]
    positions: np.ndarray
    peak_speed: np.ndarray
    t_peak: np.ndarray
    arrival_time: np.ndarray
    energy_drift: float
    far_wall_reached: bool

    @classmethod
    def of(cls, analysis: ImpactAnalysis) -> ImpactResult:
        r = analysis.results
        lines = {
            name: LineResult(beads + 1, r.peak_speed[beads], r.t_peak[beads], r.arrival_time[beads])
            for name, beads in r.lines.items()
        }
        return cls(
            r.units, lines, r.positions, r.peak_speed, r.t_peak, r.arrival_time, r.energy_drift, r.far_wall_reached
        )


def simulate_impact(config: RunConfig | None = None, out=None, verbose: bool = False, **changes) -> ImpactResult:
    """Simulate one impact of ``config`` (default: the paper's experiment) with ``changes``
    applied (RunConfig field names, e.g. ``edge_beads=7, v0=0.7``).

    Nothing is written unless ``out`` is given; then ``out`` receives the files of ``hexdem
    run`` (deck, ``peaks.csv``, ``summary.json``, figures). ``verbose`` prints progress. A key that
    the others leave without effect is refused, as ``hexdem run`` refuses it
    (:func:`~hexdem.model.unused_keys.check_unused_keys`).
    """
    config = (config or RunConfig()).override(**changes)
    check_unused_keys(config)
    log = (lambda message: sys.stderr.write(f"hexdem: {message}\n")) if verbose else (lambda message: None)
    if out is not None:
        return ImpactResult.of(run_experiment(config, out, log))
    with tempfile.TemporaryDirectory(prefix="hexdem-") as scratch:
        return ImpactResult.of(simulate(config, scratch, log))


def tca() -> dict:
    """ω, c and the TCA's residence time at V₀ = 1 (nondimensional; Sec. IV, eq. (6))."""
    return _tca.summary()


def scaling_laws(
    settings: SweepSettings | None = None, last: int | None = None, kind: str = "loglinear"
) -> dict[str, CombinationFit]:
    """Run the V₀ sweep of ``settings`` (default: Sec. V's, on the reference integrator) and fit
    the laws of the four combinations "30/30", "30/0", "0/0", "0/30" (window up to ``last``).

    Each :class:`~hexdem.theory.scaling.CombinationFit` has ``rate["m"]``, ``rate["b"]`` (c = m V₀
    + b), ``ratio`` (α, β[, γ]) with standard errors (``rate.error("m")``) and ``law``.
    Spawns worker processes: call it under ``if __name__ == "__main__":`` in scripts.
    """
    sweep = run_sweep(settings or SweepSettings(), log=lambda message: None)
    return {name: sweep.fit(combination, last, kind) for name, combination in COMBINATIONS.items()}
