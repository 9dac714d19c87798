"""Convergence in the time step, for both engines: why the default is 140 steps per contact.

Usage: python benchmarks/bench_accuracy.py [--quick]

For each case, the same run at several numbers of steps per two-bead Hertz contact time (the
sampling interval fixed at 1/20 of it), each measured against the Richardson-extrapolated answer
of its two finest runs (:mod:`hexdem.experiments.convergence`): the largest relative peak-speed
error and the largest arrival-time error over the observation lines' beads above 1 % of V0, the
energy drift, the observed order of the peak error, and the run's wall time. Cases:

* the paper's experiment (11 per edge, 0.4 m/s, delrin walls), LAMMPS (velocity Verlet) and the
  reference integrator (RK4);
* the V0 sweep's runs (nondimensional, no walls) at its smallest and largest V0, 0.01 and 0.30,
  LAMMPS;
* and, for the growth of the arrival-time error with the time t the pulse has travelled, a 150-bead
  chain struck along its axis (``convergence.CHAIN``, the fastest growth), LAMMPS. For it and every
  LAMMPS case the bound |error| <= (floor τ + rate t)/N²
  (:func:`~hexdem.experiments.convergence.arrival_growth`) is printed beside the constants of
  ``hexdem compare``'s tolerances.

Target: at the default steps per contact, peaks within 1e-4 and arrival times within 0.05 µs
(in contact times: 7e-4 τ, the same share of the contact at every V0) of the converged answer,
the step's error plus the sampling's (the default run against the same run sampled at every step,
:func:`~hexdem.experiments.convergence.sampling_error`).
``--quick``: a 5-per-edge hexagon and three steps per contact (the same code path, seconds).
"""

from __future__ import annotations

import argparse
import tempfile

from machine import describe

from hexdem.experiments.compare import ARRIVAL_ERROR_N2, ARRIVAL_GROWTH_N2
from hexdem.experiments.convergence import CHAIN, arrival_growth, sampling_error, study_time_step
from hexdem.model.config import STEPS_PER_CONTACT, RunConfig
from hexdem.model.model_builder import build_model
from hexdem.model.run_settings import contact_time_s

PEAK_TARGET = 1e-4
ARRIVAL_TARGET_S = 0.05e-6


def cases(quick: bool) -> list[tuple[str, RunConfig, tuple[int, ...]]]:
    if quick:
        return [
            ("experiment, 5 per edge", RunConfig(edge_beads=5), (80, STEPS_PER_CONTACT, 280)),
            ("experiment, 5 per edge", RunConfig(edge_beads=5, engine="reference"), (80, STEPS_PER_CONTACT, 280)),
        ]
    sweep = RunConfig(edge_beads=16, wall_material="none", units="nondimensional")
    return [
        ("experiment", RunConfig(), (40, 80, 100, STEPS_PER_CONTACT, 200, 400, 800)),
        ("experiment", RunConfig(engine="reference"), (40, 80, 100, STEPS_PER_CONTACT, 200, 400, 800)),
        ("sweep, V0 = 0.01", sweep.replace(v0=0.01), (40, 80, STEPS_PER_CONTACT, 280, 560)),
        ("sweep, V0 = 0.30", sweep.replace(v0=0.30), (40, 80, STEPS_PER_CONTACT, 280, 560)),
    ]


def growth_verdict(name: str, study) -> str:
    """The study's bound on the arrival-time error as the pulse travels, beside hexdem compare's."""
    growth = arrival_growth(study)
    return (
        f"{name}, {study.engine}: arrival error <= ({growth.floor:.3f} τ + {growth.rate:.3f} t)/N² over "
        f"t <= {study.arrivals.max():.0f} τ (hexdem compare's tolerances: {ARRIVAL_ERROR_N2} and "
        f"{ARRIVAL_GROWTH_N2})"
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small packing, three steps (seconds)")
    args = parser.parse_args()
    tau_experiment = contact_time_s(RunConfig(), build_model(RunConfig()))
    arrival_target = ARRIVAL_TARGET_S / tau_experiment
    print(f"machine: {describe()}")
    print(
        f"errors against the Richardson extrapolation of each case's two finest runs; default: "
        f"{STEPS_PER_CONTACT} steps per contact; contact time τ at V0; order: of the peak error from a row to the next"
    )
    print(
        f"{'case':<24} {'engine':<10} {'steps/τ':>8} {'peak error':>11} {'arrival [µs]':>13} "
        f"{'arrival [τ]':>12} {'energy drift':>13} {'order':>6} {'wall [s]':>9}"
    )
    verdicts = []
    with tempfile.TemporaryDirectory(prefix="hexdem-accuracy-") as scratch:
        for k, (name, config, steps) in enumerate(cases(args.quick)):
            study = study_time_step(config, steps, f"{scratch}/{k}")
            contact_s = contact_time_s(config, build_model(config))
            orders = [f"{order:6.2f}" for order in study.observed_orders] + [f"{'-':>6}"] * 2
            for run, order in zip(study.runs, orders):
                micro = (
                    f"{run.arrival_error_contacts * contact_s * 1e6:13.2e}" if config.units == "si" else f"{'-':>13}"
                )
                print(
                    f"{name:<24} {config.engine:<10} {run.steps_per_contact:8d} {run.peak_error:11.2e} {micro} "
                    f"{run.arrival_error_contacts:12.2e} {run.energy_drift:13.2e} {order} {run.wall_time_s:9.2f}"
                )
            default, sampled = study.at(STEPS_PER_CONTACT), sampling_error(config, f"{scratch}/{k}-sampling")
            sampled_contacts = sampled.arrival_error / (contact_s / config.unit_system.time_s)
            peak, arrival = default.peak_error + sampled.peak_error, default.arrival_error_contacts + sampled_contacts
            met = peak < PEAK_TARGET and arrival < arrival_target
            verdicts.append(
                f"{name}, {config.engine}: step + sampling every {sampled.dump_every} steps: peak "
                f"{default.peak_error:.1e} + {sampled.peak_error:.1e}, arrival "
                f"{default.arrival_error_contacts:.1e} + {sampled_contacts:.1e} τ: {'met' if met else 'NOT met'}"
            )
            if study.order == 2:
                verdicts.append(growth_verdict(name, study))
        verdicts.append(
            growth_verdict(
                "chain, 150 beads", study_time_step(CHAIN, (80, STEPS_PER_CONTACT, 280, 560), f"{scratch}/chain")
            )
        )
    print(
        f"target at {STEPS_PER_CONTACT} steps per contact: peaks within {PEAK_TARGET:g}, arrival within "
        f"{ARRIVAL_TARGET_S * 1e6:g} µs ({arrival_target:.1e} τ), the step's error and the sampling's "
        f"(against sampling every step) together"
    )
    for line in verdicts:
        print(f"  {line}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
