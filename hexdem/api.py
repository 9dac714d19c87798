"""hexdem's Python API: the few names a script or a notebook needs (``import hexdem``).

* :class:`RunConfig` — one impact simulation (the paper's experiment by default);
* :func:`simulate_impact` — run it and get arrays back (peak speed, time of peak and arrival
  time along each observation line, energy drift), writing files only if asked;
* :func:`tca` — ω and c of the ternary collision approximation (Sec. IV);
* :class:`SweepSettings` and :func:`scaling_laws` — the V₀ sweep of Sec. V and the fitted
  laws (9), (10), (11) of the four strike/observation combinations;
* :func:`calibrate` and :class:`Posterior` — the model's parameters from a lab's sensor records
  (``hexdem calibrate``), the posterior's draws, intervals, fit and diagnostics, and the posterior
  as an ArviZ ``DataTree`` (:meth:`Posterior.to_inference_data`).
"""

from __future__ import annotations

import json
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hexdem.analysis.impact import ImpactAnalysis
from hexdem.api_names import API_NAMES
from hexdem.experiments.run import run_experiment, simulate
from hexdem.model.config import RunConfig
from hexdem.model.unused_keys import check_unused_keys
from hexdem.theory import tca as _tca
from hexdem.theory.scaling import COMBINATIONS, CombinationFit
from hexdem.theory.sweep import SweepSettings, run_sweep

__all__ = list(API_NAMES)


@dataclass(frozen=True)
class LineResult:
    """One observation line of an impact, bead n = 0 (the struck bead) first.

    Every array has one entry per bead of the line (L,), in the run's units (:attr:`ImpactResult.units`).

    Attributes
    ----------
    bead_id : numpy.ndarray of int, shape (L,)
        The beads' ids, 1-based as in the LAMMPS decks.
    peak_speed : numpy.ndarray of float, shape (L,)
        Each bead's largest speed |v| during the run [m/s, or V₀'s unit when nondimensional].
    t_peak : numpy.ndarray of float, shape (L,)
        When each bead reached it [s, or the nondimensional time].
    arrival_time : numpy.ndarray of float, shape (L,)
        When the leading wave reached each bead (half its peak speed; NaN where it never came).
    """

    bead_id: np.ndarray
    peak_speed: np.ndarray
    t_peak: np.ndarray
    arrival_time: np.ndarray


@dataclass(frozen=True)
class ImpactResult:
    """What :func:`simulate_impact` returns: the pulse's peaks and arrivals at every bead.

    Attributes
    ----------
    units : str
        ``"si"`` (m, s, m/s) or ``"nondimensional"`` (d = 1, the bead's mass 1, Hertz's A = 1; Sec. II).
    lines : dict of str to LineResult
        The observation lines ``"0"``, ``"+30"`` and ``"-30"`` (degrees from the strike; Fig. 1).
    positions : numpy.ndarray of float, shape (N, 2)
        The N beads' positions as packed [m, or d].
    peak_speed : numpy.ndarray of float, shape (N,)
        Each bead's largest speed during the run.
    t_peak : numpy.ndarray of float, shape (N,)
        When each bead reached it.
    arrival_time : numpy.ndarray of float, shape (N,)
        When the leading wave reached each bead (NaN where it never came).
    energy_drift : float
        The largest relative change of the total energy, max |E − E₀| / E₀ (0 for an exact
        conservative integration; Tsuji's damping or friction make it the energy lost).
    far_wall_reached : bool
        Whether the leading wave reached the wall facing the strike.
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
    """Simulate one impact of ``config`` with ``changes`` applied, on the engine it names.

    Parameters
    ----------
    config : RunConfig, optional
        The simulation (default: the paper's experiment, an 11-per-edge steel hexagon struck at
        V₀ = 0.42 m/s along 0°).
    out : str or pathlib.Path, optional
        A folder to receive the files of ``hexdem run`` (deck, ``peaks.csv``, ``summary.json``,
        figures); nothing is written without it.
    verbose : bool, default False
        Print progress to standard error.
    **changes
        :class:`RunConfig` keys and their values, e.g. ``edge_beads=7, v0=0.7`` (V₀ in ``units``).

    Returns
    -------
    ImpactResult
        Peaks and arrivals at every bead and along the observation lines.

    Raises
    ------
    hexdem.errors.HexdemError
        A configuration that is refused, or a key that the others leave without effect, as
        ``hexdem run`` refuses it (:func:`~hexdem.model.unused_keys.check_unused_keys`).
    hexdem.errors.RunFailed
        An engine that failed, or a run whose energy drifted.
    """
    config = (config or RunConfig()).override(**changes)
    check_unused_keys(config)
    log = (lambda message: sys.stderr.write(f"hexdem: {message}\n")) if verbose else (lambda message: None)
    if out is not None:
        return ImpactResult.of(run_experiment(config, out, log))
    with tempfile.TemporaryDirectory(prefix="hexdem-") as scratch:
        return ImpactResult.of(simulate(config, scratch, log))


def tca() -> dict:
    """The ternary collision approximation's numbers (Sec. IV, eq. (6)).

    Returns
    -------
    dict
        ``omega`` (ω, the compatibility condition's root), ``c`` (the decay factor per layer),
        ``residence_time_at_v0_1`` (nondimensional; it scales as :math:`V_0^{-1/5}`), and the
        rest of :func:`hexdem.theory.tca.summary`; nondimensional, A = d = M = 1.
    """
    return _tca.summary()


def scaling_laws(
    settings: SweepSettings | None = None, last: int | None = None, kind: str = "loglinear"
) -> dict[str, CombinationFit]:
    """Run the V₀ sweep of Sec. V and fit the scaling laws (9), (10), (11).

    Spawns worker processes: call it under ``if __name__ == "__main__":`` in scripts.

    Parameters
    ----------
    settings : SweepSettings, optional
        The sweep (default: Sec. V's, nondimensional V₀ from 0.01 to 0.30, on the reference integrator).
    last : int, optional
        The last bead any fit may use (default: ``settings.last``).
    kind : {"loglinear", "nonlinear"}, default "loglinear"
        How each V₀'s decay V_n = V_s cⁿ is fitted.

    Returns
    -------
    dict of str to CombinationFit
        The combinations ``"30/30"``, ``"30/0"``, ``"0/0"``, ``"0/30"`` (strike/observation lines),
        each with ``rate["m"]``, ``rate["b"]`` (c = m V₀ + b), ``ratio`` (α, β[, γ]), their
        standard errors (``rate.error("m")``) and the fitted ``law``.
    """
    sweep = run_sweep(settings or SweepSettings(), log=lambda message: None)
    return {name: sweep.fit(combination, last, kind) for name, combination in COMBINATIONS.items()}


@dataclass(frozen=True)
class Posterior:
    """What :func:`calibrate` returns: the posterior of the calibrated keys, as ``hexdem calibrate``
    writes it into its folder (``posterior.csv`` and ``calibration.json``).

    Attributes
    ----------
    keys : tuple of str
        The calibrated keys, in the order of the priors.
    samples : numpy.ndarray of float, shape (n, p)
        The posterior's draws of the keys, in their units (σ in m, V₀ in m/s), ``chains`` blocks of
        equal length one after the other.
    chains : int
        The sampler's independent chains.
    summary : dict
        ``calibration.json``: per key its prior, median and 90 % interval, ``fit``, ``convergence``,
        ``model_discrepancy``, ``warnings`` and the rest (the calibration guide lists them).
    folder : pathlib.Path
        The calibration's folder.
    """

    keys: tuple[str, ...]
    samples: np.ndarray
    chains: int
    summary: dict
    folder: Path

    @classmethod
    def read(cls, folder) -> Posterior:
        """The posterior of the finished calibration in ``folder``.

        Parameters
        ----------
        folder : str or pathlib.Path
            The ``--out`` of ``hexdem calibrate``.

        Returns
        -------
        Posterior
        """
        folder = Path(folder)
        summary = json.loads((folder / "calibration.json").read_text())
        samples = np.loadtxt(folder / "posterior.csv", delimiter=",", skiprows=1, ndmin=2)
        return cls(tuple(summary["parameters"]), samples, int(summary["method"]["chains"]), summary, folder)

    @property
    def intervals(self) -> dict[str, tuple[float, float]]:
        """Each key's 90 % central interval (5 % and 95 % quantiles), in its unit."""
        return {key: (entry["q05"], entry["q95"]) for key, entry in self.summary["parameters"].items()}

    @property
    def medians(self) -> dict[str, float]:
        """Each key's posterior median, in its unit."""
        return {key: entry["median"] for key, entry in self.summary["parameters"].items()}

    @property
    def fit(self) -> dict:
        """Whether the model fits the records: ``chi2``, ``dof``, ``p_value``, ``predictive_p_value``, per record."""
        return self.summary["fit"]

    @property
    def convergence(self) -> dict:
        """How the chains mixed: ``rhat``, ``ess_bulk``, ``ess_tail``, ``autocorrelation_lengths``, ``converged``."""
        return self.summary["convergence"]

    @property
    def warnings(self) -> list[str]:
        """What the calibration says not to trust, one sentence each (empty when all checks pass)."""
        return self.summary["warnings"]

    def to_inference_data(self):
        """The posterior as ArviZ's ``DataTree`` (the successor of ``InferenceData``).

        Returns
        -------
        xarray.DataTree
            A ``posterior`` group with one variable per key, of dimensions (chain, draw), so that
            ArviZ's diagnostics and plots (and ``.to_netcdf(PATH)``) work on it.

        Raises
        ------
        ImportError
            Without ArviZ's base package: ``pip install 'hexdem[arviz]'``.
        """
        import arviz_base

        draws = self.samples.reshape(self.chains, -1, len(self.keys))
        posterior = {key: draws[:, :, j] for j, key in enumerate(self.keys)}
        return arviz_base.from_dict(
            {"posterior": posterior}, attrs={"posterior": {"hexdem_calibration": str(self.folder)}}
        )


def calibrate(
    measured,
    priors,
    out,
    config=None,
    *,
    budget: int | None = None,
    seed: int = 0,
    realizations: int | None = None,
    sensor_gain_sd: float | None = None,
    speed_scatter: float | None = None,
    acceleration_unit: str = "m/s2",
    model_discrepancy: bool = True,
    workers: int = 1,
    verbose: bool = False,
) -> Posterior:
    """Calibrate the model's parameters from measured sensor records, as ``hexdem calibrate`` does.

    Spawns worker processes with ``workers`` > 1: call it under ``if __name__ == "__main__":`` in scripts.

    Parameters
    ----------
    measured : str or pathlib.Path
        The records: a CSV of columns ``sensor,time,ax[,ay][,record]`` (times in s).
    priors : list of str
        One ``KEY=DIST`` per calibrated key, e.g. ``"restitution=uniform(0.8, 1.0)"``,
        ``"diameter_sigma_m=uniform(0, 1.5e-4)"`` (σ of the diameters [m]: disordered packings).
    out : str or pathlib.Path
        The calibration's folder; calling again with the same arguments resumes it.
    config : str, pathlib.Path or dict, optional
        The base configuration: a TOML file, or its keys (default: the paper's experiment); its
        ``sensors`` are the measured ones.
    budget : int, optional
        Simulations in all (default: (30 per key + 30) × the packings per parameter set).
    seed : int, default 0
        Every random choice: the same seed, records and simulations give the same posterior.
    realizations : int, optional
        Packings per parameter set (default: 8 with a prior on ``diameter_sigma_m``, else 1).
    sensor_gain_sd, speed_scatter : float, optional
        The sensors' gains' and the striker's speed's relative standard deviations (defaults 0.02
        and 0.01, as the command's).
    acceleration_unit : {"m/s2", "g"}, default "m/s2"
        The records' unit.
    model_discrepancy : bool, default True
        Sample a relative model error τ with the parameters (Kennedy & O'Hagan's discrepancy).
    workers : int, default 1
        Simulations at once.
    verbose : bool, default False
        Print progress to standard error.

    Returns
    -------
    Posterior
        Its draws, intervals, fit, convergence and warnings.

    Raises
    ------
    hexdem.errors.HexdemError
        Input the command refuses (a prior, a record, a budget), before any simulation.
    """
    from hexdem.calibration.study import DEFAULT_GAIN_SD, DEFAULT_SPEED_SCATTER, prepare
    from hexdem.calibration.study import calibrate as run_calibration
    from hexdem.experiments.sweep_plan import read_base

    base = dict(config) if isinstance(config, dict) else read_base(None if config is None else str(config))
    calibration = prepare(
        base,
        measured,
        list(priors),
        budget,
        seed,
        realizations,
        DEFAULT_GAIN_SD if sensor_gain_sd is None else sensor_gain_sd,
        DEFAULT_SPEED_SCATTER if speed_scatter is None else speed_scatter,
        acceleration_unit,
        model_discrepancy,
    )
    log = (lambda message: sys.stderr.write(f"hexdem: {message}\n")) if verbose else (lambda message: None)
    run_calibration(calibration, measured, out, workers, None, log)
    return Posterior.read(out)
