"""Time step, step count and sampling of a run, with the defaults resolved from its model.

The natural time scale is the impacts' Hertz contact time (:func:`contact_time_s`). The
default step is that time over ``steps_per_contact``, the default sampling interval a 1/20 of
it, and the default duration follows the pulse across the packing layer by layer
(:func:`~hexdem.model.timescale.crossing_time_s`). :func:`run_settings` also refuses a step
that does not resolve the contact, or too few samples to analyse.
"""

from __future__ import annotations

import math

from hexdem.errors import HexdemError
from hexdem.model.config import MIN_STEPS_PER_CONTACT
from hexdem.model.granular import GranularModel, RunSettings
from hexdem.model.packing_builders import PLACED_SHAPES, ROW_CRYSTAL_SHAPES
from hexdem.model.timescale import (
    crossing_time_s,
    fastest_approach_m_s,
    impact_contact_time_s,
    sized_bodies,
    solitary_crossing_time_s,
    striker_launch_s,
    wall_contact_time_s,
)

#: Samples per contact time, whatever the step (every 3.6 µs at 0.4 m/s; its error with the step's
#: stays inside the targets: ``convergence.sampling_error``); default ``dump_every``:
#: ``steps_per_contact`` / this.
SAMPLES_PER_CONTACT = 20
#: The analysis needs at least this many samples per contact time at V0, and this many in all.
MIN_SAMPLES_PER_CONTACT = 4
MIN_SAMPLES = 10


def contact_time_s(config, model: GranularModel) -> float:
    """The natural time scale of ``config``'s impacts [s]
    (:func:`~hexdem.model.timescale.impact_contact_time_s`): the shortest two-body Hertz contact
    time at an impact's V0 or at the initial state's fastest approach (read on ``model``, the
    model built from ``config``), or, if shorter, half the period of two beads on the linearized
    precompressed contact."""
    strikers = [
        (
            spec.v0 * config.unit_system.velocity_m_s,
            (
                config.material(spec.striker_material or config.bead_material),
                spec.striker_diameter_m or config.diameter_m,
            )
            if spec.striker and (spec.striker_material is not None or spec.striker_diameter_m is not None)
            else None,
        )
        for spec in config.impact_specs()
    ]
    if config.initial_state_file is not None:
        fastest = fastest_approach_m_s(model)
        strikers += [(fastest, striker) for _, striker in strikers]
    sized = () if config.shape not in PLACED_SHAPES else sized_bodies(model)
    return impact_contact_time_s(
        config.material(config.bead_material),
        config.diameter_m,
        [config.material(r["material"]) for r in config.regions],
        strikers,
        config.precompression_n,
        sized,
    )


def rebound_time_s(model: GranularModel, contact_s: float) -> float:
    """The default duration [s] when nothing lies ahead of the struck beads (a single bead, a
    row struck along its normal): the longest of each struck bead's head-on Hertz contacts with
    the walls at its impact's speed (:func:`~hexdem.model.timescale.wall_contact_time_s`), plus one
    contact time ``contact_s`` [s], so that the run holds the whole rebound and the bead's flight
    after it."""
    return contact_s + wall_contact_time_s(model)


def step_and_sampling(config, contact_s: float) -> tuple[float, int]:
    """(dt [s], steps between samples): ``dt`` or the contact time ``contact_s`` over
    ``steps_per_contact``, and ``dump_every`` or the steps of one default sampling interval (1/20
    of the contact time), the default step shortened so that this interval is whole steps."""
    interval_s = contact_s / SAMPLES_PER_CONTACT
    if config.dt is not None:
        dt_s = config.dt * config.unit_system.time_s
        return dt_s, config.dump_every or max(1, round(interval_s / dt_s))
    if config.dump_every is not None:
        return contact_s / config.steps_per_contact, config.dump_every
    every = math.ceil(config.steps_per_contact / SAMPLES_PER_CONTACT)
    return interval_s / every, every


def check_sampling(config, settings: RunSettings) -> None:
    """Refuse a time step that does not resolve the Hertz contact, or too few samples."""
    contact_s = settings.contact_time_s
    scale = config.unit_system.time_s
    if settings.dt_s > contact_s / MIN_STEPS_PER_CONTACT:
        raise HexdemError(
            f"time step {settings.dt_s / scale:.3g} is not small against the Hertz contact time "
            f"{contact_s / scale:.3g} at V0 (in {config.units} units): use dt <= "
            f"{contact_s / scale / MIN_STEPS_PER_CONTACT:.3g}, or leave dt at its default"
        )
    interval_s = settings.dt_s * settings.dump_every
    if settings.n_samples < MIN_SAMPLES or interval_s > contact_s / MIN_SAMPLES_PER_CONTACT:
        raise HexdemError(
            f"too few samples to analyse: {settings.n_samples} samples, one every "
            f"{interval_s / scale:.3g} (contact time {contact_s / scale:.3g}); need at least "
            f"{MIN_SAMPLES} and {MIN_SAMPLES_PER_CONTACT} per contact time: lower dump_every "
            "or lengthen duration"
        )


def run_settings(config, model: GranularModel) -> RunSettings:
    """Time step, step count and dump interval of ``config`` in SI, with the defaults resolved
    on ``model`` (the model built from ``config``), checked by :func:`check_sampling`. With sensors, the time
    step is shortened (at most by one sample's worth) so that a sensor sample is a whole number
    of analysis samples of ``dump_every`` steps."""
    scale = config.unit_system.time_s
    contact_s = contact_time_s(config, model)
    dt_s, every = step_and_sampling(config, contact_s)
    if config.duration is not None:
        duration_s = config.duration * scale
    elif config.shape in ROW_CRYSTAL_SHAPES:
        duration_s = solitary_crossing_time_s(model, contact_s, wall_contact_time_s(model)) + striker_launch_s(model)
    else:
        crossing_s = crossing_time_s(model, contact_s if config.precompression_n > 0 else None)
        duration_s = crossing_s + striker_launch_s(model) if crossing_s > 0 else rebound_time_s(model, contact_s)
    sensor_every = 0
    if config.sensors:
        samples = math.ceil(1.0 / config.sensor_rate_hz / (dt_s * every) - 1e-9)
        sensor_every = samples * every
        dt_s = 1.0 / config.sensor_rate_hz / sensor_every
    n_steps = max(1, round(duration_s / dt_s))
    settings = RunSettings(
        dt_s=dt_s,
        n_steps=n_steps,
        dump_every=every,
        units=config.unit_system,
        sensor_every=sensor_every,
        contact_time_s=contact_s,
    )
    check_sampling(config, settings)
    return settings
