"""One impact simulation end to end: config → engine → analysis → result files.

:func:`run_experiment` builds and checks the model, runs the engine and writes every result into
a fresh hidden folder of ``OUT`` and, only when the run and its analysis succeeded, moves into
``OUT`` the deck ``OUT/deck`` (inputs, log, the dump if asked for), a random disc's packing
``OUT/preparation`` (its LAMMPS decks and ``packing.csv``,
:mod:`~hexdem.experiments.random_packing`) and
:data:`RESULT_FILES` (``peaks.csv``
along the observation lines, ``beads.csv`` of every bead, ``summary.json``, the arrival and
peak maps, ``peak_decay.png``, ``front_shape.csv`` and ``.png``, ``energy_regions.csv``), with
``energy_regions.png`` when the beads are of several materials and ``movie.gif`` on request
(with ``spin_movie.gif`` for frictional spheres, which turn),
each written atomically. An output that cannot be measured on the packing (a chain has no 2D
front; a single bead no decay along a line) is skipped, and ``summary.json`` says which and why
(:func:`unmeasurable_outputs`). A failed run leaves nothing in ``OUT`` (an ``OUT`` it created is
removed again); its inputs and log are kept in a ``hexdem-failed-*`` folder of the system's
temporary directory, which the error message names. A full disk is one line naming ``OUT``, and
a run stopped by a signal (:mod:`hexdem.common.interrupt`) leaves nothing in ``OUT`` either.
"""

from __future__ import annotations

import errno
import shutil
import sys
import tempfile
import time
from importlib.metadata import version
from pathlib import Path

import numpy as np

from hexdem.analysis.front_shape import FRONT_SHAPE_COLUMNS, FrontShape, front_shape, front_times, front_unmeasurable
from hexdem.analysis.impact import PEAK_COLUMNS, ImpactAnalysis
from hexdem.analysis.movie import movie_samples
from hexdem.common.forked import run_shared
from hexdem.common.interrupt import raise_if_stopped
from hexdem.common.io import staged_directory, write_csv, write_csv_columns, write_json
from hexdem.common.machine import free_disk_bytes
from hexdem.common.preload import load_in_background
from hexdem.errors import HexdemError, RunFailed
from hexdem.experiments.deck_config import write_deck_config
from hexdem.experiments.provenance import started_provenance
from hexdem.experiments.random_packing import packing_name, prepare_random_packing
from hexdem.experiments.sensors import write_sensor_files
from hexdem.experiments.tracked_run import ImpactJob, track_impact
from hexdem.model.config import RunConfig
from hexdem.model.granular import GranularModel, RunSettings
from hexdem.model.model_builder import build_model
from hexdem.model.run_settings import run_settings
from hexdem.model.sensors import sensor_beads

RESULT_FILES = (
    "peaks.csv",
    "summary.json",
    "arrival_map.png",
    "peak_decay.png",
    "front_shape.csv",
    "front_shape.png",
    "energy_regions.csv",
    "beads.csv",
    "peak_map.png",
)
#: Columns of ``beads.csv``: every bead's label, position, material and pulse, its largest
#: spin |ω_z| (run's units: rad/s in SI; 0 for frictionless spheres, which never turn) and its
#: velocity at the run's last sample (a rebound's outgoing velocity).
BEAD_COLUMNS = (
    "bead_id",
    "m",
    "n",
    "x",
    "y",
    "material",
    "peak_speed",
    "t_peak",
    "arrival_time",
    "peak_angular_speed",
    "vx_end",
    "vy_end",
)
#: Columns of ``energy_regions.csv``: time in the run's units, energies in J, share of the total.
ENERGY_REGION_COLUMNS = ("time", "region", "kinetic_energy_j", "contact_energy_j", "energy_fraction")
#: Bytes per atom and frame of a full-precision dump (measured: 30 MB for 331 atoms x 701 frames).
DUMP_BYTES_PER_ATOM_FRAME = 150
#: A conservative model whose energy wanders more than this was integrated too coarsely.
MAX_ENERGY_DRIFT = 1e-3
#: A run writes everything into a fresh ``OUT/.hexdem-run-*`` folder and moves it into ``OUT`` at the end.
STAGING_PREFIX = ".hexdem-run-"
#: What a finished run warns of, by the name that study tables (``warnings`` columns) give it.
RUN_WARNINGS = {
    "far_wall_not_reached": "the leading wave had not reached every bead at the far wall one contact "
    "time before the run ended; increase 'duration'"
}
#: A failed run's deck is kept in a folder of the temporary directory named so.
FAILED_PREFIX = "hexdem-failed-"
#: The front is read along each direction until it comes this close to the packing's edge [d]:
#: the last bead before a wall moves as the wall lets it.
FRONT_WALL_MARGIN_D = 2.0


def simulate(config: RunConfig, workdir, log=None, **observed) -> ImpactAnalysis:
    """:func:`simulate_model` of ``config`` on the model and settings built from it; ``observed``:
    what to record in the run (:func:`simulate_model`'s ``trace_lines`` and the others)."""
    model = build_model(config)
    return simulate_model(config, model, run_settings(config, model), workdir, log, **observed)


def simulate_model(
    config: RunConfig,
    model: GranularModel,
    settings: RunSettings,
    workdir,
    log=None,
    trace_lines=(),
    field_samples=(),
    trace_beads=(),
    threshold_speed: float | None = None,
) -> ImpactAnalysis:
    """Run ``config``, whose model ``model`` is and whose step, length and sampling ``settings``
    are (:func:`~hexdem.model.run_settings.run_settings`), with its engine in ``workdir``, analysed
    while it runs (no result files).

    ``trace_lines`` (observation line names) keep the speeds of those lines' beads at every
    sample, and so do ``trace_beads`` (bead indices) for theirs; ``threshold_speed`` (run units)
    records when each bead's speed first reaches it; ``field_samples`` every bead's speed at those samples (see
    :class:`~hexdem.analysis.tracker.PulseTracker`), and those of the movie's frames
    (:func:`~hexdem.analysis.movie.movie_samples`) with ``config.movie``. A LAMMPS deck directory also gets
    ``hexdem.json`` (the configuration) and a copy of its input files, which ``hexdem analyse`` reads
    (:mod:`~hexdem.experiments.deck_config`).
    """
    log = log or (lambda message: None)
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    if config.engine == "lammps":
        write_deck_config(config, workdir)
    log(
        f"running {config.engine}: {model.packing.shape}, {model.n_bodies} bodies, "
        f"{settings.n_steps} steps of {settings.dt_s:.4g} s ({settings.duration_s * 1e3:.4g} ms), "
        f"{config.processes} rank(s), {settings.n_samples} samples analysed in the run"
    )
    traced = tuple(
        dict.fromkeys(
            [
                *(int(bead) for line in trace_lines for bead in model.packing.line(line)),
                *(int(bead) for bead in trace_beads),
            ]
        )
    )
    frames = movie_samples(settings.n_samples) if config.movie else ()
    job = ImpactJob(
        model,
        settings,
        config.engine,
        workdir,
        dump=config.dump,
        trace_beads=traced,
        field_samples=tuple(sorted(set(field_samples) | set(frames))),
        threshold_speed=threshold_speed,
    )
    analysis = track_impact(job, config.ranks, config.launcher)
    check_energy(analysis, workdir)
    return analysis


def check_dump_space(config: RunConfig, model: GranularModel, settings: RunSettings, out: Path) -> None:
    """Refuse a run of ``config`` (whose model ``model`` and settings ``settings`` are) whose
    requested dump would not fit on the disk of ``out``."""
    if not (config.dump and config.engine == "lammps"):
        return
    needed = DUMP_BYTES_PER_ATOM_FRAME * settings.n_samples * model.n_bodies
    free = free_disk_bytes(out)
    if needed > free:
        raise HexdemError(
            f"the dump would take about {needed / 1e9:.3g} GB and {out} has {free / 1e9:.3g} GB free; "
            "drop dump, raise dump_every or free some space"
        )


def check_energy(analysis: ImpactAnalysis, where) -> None:
    """Refuse a run whose energy drift shows a time step too coarse for its impact.

    Not a frictional one: the audit counts the spins but not the energy Mindlin's tangential springs
    store (LAMMPS keeps their history inside its pair style), which they give back as the contacts
    unload, a rise the audit cannot tell from integration error (measured: 1.4e-3 of the impact's
    energy with μ = 0.3 at the default step). Its figure is still reported; the engines' agreement
    and convergence hold the frictional step (tests/test_friction_*.py)."""
    drift = analysis.results.energy_drift
    if not analysis.model.laws.tangential and not drift <= MAX_ENERGY_DRIFT:
        raise RunFailed(
            f"energy drift {drift:.1e} exceeds {MAX_ENERGY_DRIFT:g} in {where}: the time step "
            f"{analysis.settings.dt_s:.3g} s is too large for V0; leave dt at its default or reduce it"
        )


def summary(config: RunConfig, analysis: ImpactAnalysis, wall_time_s: float) -> dict:
    """The contents of ``summary.json``: inputs, engine, energy drift, timings."""
    r, settings, engine = analysis.results, analysis.settings, analysis.engine
    return {
        "hexdem_version": version("hexdem"),
        "config": config.shape_dict(),
        "units": r.units,
        "lattice": {
            "shape": packing_name(config, analysis.model.packing),
            "n_beads": len(analysis.model.packing),
            "struck_bead_id": analysis.model.packing.struck + 1,
        },
        "time_step": settings.dt_s / settings.units.time_s,
        "n_steps": settings.n_steps,
        "duration": settings.duration_s / settings.units.time_s,
        "dump_every": settings.dump_every,
        "n_samples": settings.n_samples,
        "analysis": "in the run" if analysis.tracked is not None else "from the dump",
        "engine": engine.get("name"),
        "lammps_version": engine.get("version") if engine.get("name") == "lammps" else None,
        "ranks": engine.get("ranks"),
        "collectives": analysis.tracked.collectives if analysis.tracked is not None else None,
        "analysis_cpu_s": analysis.tracked.analysis_cpu_s if analysis.tracked is not None else None,
        "engine_wall_time_s": engine.get("wall_time_s"),
        "wall_time_s": wall_time_s,
        "energy_drift": r.energy_drift,
        "energy_lost": analysis.tracked.energy_lost if analysis.tracked is not None else None,
        "rotational_energy_fraction": r.rotational_energy_fraction,
        "far_wall_reached": r.far_wall_reached,
        "beads_per_line": {name: len(beads) for name, beads in r.lines.items()},
        "impacts": [
            {
                "bead_id": int(bead) + 1,
                "site": [int(v) for v in analysis.model.packing.labels[bead]],
                "v0": impact.speed_m_s / settings.units.velocity_m_s,
                "angle_deg": float(impact.angle_deg),
                "kind": "striker" if impact.striker else "velocity",
            }
            for bead, impact in zip(analysis.model.struck_beads, analysis.model.impacts)
        ],
    }


def unmeasurable_outputs(analysis: ImpactAnalysis) -> dict[str, str]:
    """{result file: why it cannot be measured on this run's packing}: the front's shape needs
    arrivals spread over the plane (:func:`~hexdem.analysis.front_shape.front_unmeasurable`), and a
    decay along the observation lines needs a line of two beads or more."""
    r = analysis.results
    skipped = {}
    front = front_unmeasurable(r.positions, r.arrival_time)
    if front is not None:
        skipped.update({"front_shape.csv": front, "front_shape.png": front})
    if max(len(beads) for beads in r.lines.values()) < 2:
        skipped["peak_decay.png"] = "no observation line holds two beads or more: there is no decay to draw"
    return skipped


def write_results(
    config: RunConfig, analysis: ImpactAnalysis, out: Path, wall_time_s: float, provenance: dict, log=None
) -> None:
    """Every result file of the run (see the module docstring), each written atomically; those
    that cannot be measured on the packing are skipped, named with their reason in
    ``summary.json``'s ``skipped_outputs`` and in the ``log``. ``provenance``
    (:func:`~hexdem.experiments.provenance.run_provenance`, taken when the run started) goes into
    ``summary.json`` as its ``provenance``."""
    from hexdem.analysis import plotting as plots  # matplotlib: only where figures are drawn
    from hexdem.analysis.decay_figure import peak_decay
    from hexdem.analysis.movie import SPIN_LABEL, speed_movie
    from hexdem.analysis.run_maps import arrival_map, peak_map

    log = log or (lambda message: None)
    skipped = unmeasurable_outputs(analysis)
    for name, reason in skipped.items():
        log(f"skipped {name}: {reason}")
    rows = analysis.line_rows()
    write_csv(out / "peaks.csv", PEAK_COLUMNS, rows)
    write_csv_columns(out / "beads.csv", BEAD_COLUMNS, bead_columns(analysis))
    write_json(
        out / "summary.json",
        {**summary(config, analysis, wall_time_s), "skipped_outputs": skipped, "provenance": provenance},
    )
    r, model = analysis.results, analysis.model
    v0, name = analysis.v0, packing_name(config, model.packing)
    if config.sensors:
        write_sensor_files(analysis, list(sensor_beads(config.sensors, analysis.model.packing)), out)
    write_csv(out / "energy_regions.csv", ENERGY_REGION_COLUMNS, energy_region_rows(r))
    impact = f"V₀ = {v0:g} {plots.UNIT_LABELS[r.units]['speed']}"
    jobs = [
        lambda: arrival_map(r, model, out / "arrival_map.png", title=f"Arrival time, {name}, {impact}"),
        lambda: peak_map(r, model, v0, out / "peak_map.png", title=f"Peak speed, {name}, {impact}"),
    ]
    if "peak_decay.png" not in skipped:
        by_line = {name: (np.arange(len(beads)), r.peak_speed[beads]) for name, beads in r.lines.items()}
        jobs.append(lambda: peak_decay(by_line, out / "peak_decay.png", r.units, v0))
    if "front_shape.csv" not in skipped:
        jobs.append(lambda: write_front_shape(analysis, name, out))
    if analysis.model.extra_materials:
        jobs.append(
            lambda: plots.energy_regions_figure(
                r, out / "energy_regions.png", title=f"Where the energy is, {', '.join(r.region_names)}"
            )
        )
    tracked = analysis.tracked
    if config.movie and tracked is not None and len(tracked.field_times):  # (a dump read back has no fields)
        jobs.append(
            lambda: speed_movie(r, model, tracked.field_times, tracked.field_speeds, v0, out / "movie.gif", title=name)
        )
        if len(tracked.field_rim_speeds):
            jobs.append(
                lambda: speed_movie(
                    r,
                    model,
                    tracked.field_times,
                    tracked.field_rim_speeds,
                    v0,
                    out / "spin_movie.gif",
                    title=name,
                    label=SPIN_LABEL,
                )
            )
    plots.tile_lattice(r, model)  # once for both maps, before they part
    run_shared(jobs)  # the figures and what they draw on two cores, where the machine has them


def write_front_shape(analysis: ImpactAnalysis, name: str, out: Path) -> None:
    """``front_shape.csv`` and ``front_shape.png`` (:func:`measure_front_shape`) in ``out``; ``name``:
    the packing's, for the figure's legend."""
    from hexdem.analysis import plotting as plots

    shape = measure_front_shape(analysis)
    write_csv(out / "front_shape.csv", FRONT_SHAPE_COLUMNS, shape.rows())
    plots.front_shape_figure({name: shape}, out / "front_shape.png")


def bead_columns(analysis: ImpactAnalysis) -> list:
    """Columns of ``beads.csv`` (:data:`BEAD_COLUMNS`): every bead, id from 1, with its label
    {m, n}, position, material, pulse and final velocity."""
    r, model = analysis.results, analysis.model
    names = np.array([material.name for material in model.materials])
    labels = np.asarray(model.packing.labels, int)
    return [
        np.arange(1, len(labels) + 1),
        labels[:, 0],
        labels[:, 1],
        r.positions[:, 0],
        r.positions[:, 1],
        names[model.packing.material_ids],
        r.peak_speed,
        r.t_peak,
        r.arrival_time,
        r.peak_angular_speed,
        r.end_velocity[:, 0],
        r.end_velocity[:, 1],
    ]


def energy_region_rows(results) -> list[tuple]:
    """Rows of ``energy_regions.csv``: per audited time and region, its kinetic and contact
    energy [J] and its share of the total."""
    totals = results.region_energies.sum(axis=(1, 2))
    return [
        (float(t), name, float(kinetic), float(contact), float((kinetic + contact) / total))
        for t, energies, total in zip(results.region_times, results.region_energies, totals)
        for name, (kinetic, contact) in zip(results.region_names, energies)
    ]


def measure_front_shape(
    analysis: ImpactAnalysis,
    count: int = 8,
    geometric: bool = False,
    window_deg: float | None = None,
    start_quantile: float = 0.05,
    wall_margin_d: float = FRONT_WALL_MARGIN_D,
    arrival_times=None,
) -> FrontShape:
    """Roundness of the half-maximum arrival front about the struck bead against its mean radius
    in bead diameters at ``count`` times (:func:`~hexdem.analysis.front_shape.front_times`), each
    direction read until the front comes within ``wall_margin_d`` of the packing's edge there
    (``window_deg``: only the rays of that window about +x), from the
    ``start_quantile`` of the arrival times on; no rows when the packing is too small for the
    front to grow before it meets one. ``arrival_times`` (run units; default the half-maximum
    arrivals) defines the front otherwise, for example by a fixed speed's first crossing."""
    model, r = analysis.model, analysis.results
    arrivals = r.arrival_time if arrival_times is None else np.asarray(arrival_times, float)
    positions = model.packing.positions_m / model.packing.diameter_m
    origin = positions[model.packing.struck]
    try:
        times = front_times(
            positions,
            arrivals,
            origin,
            count,
            start_quantile,
            wall_margin=wall_margin_d,
            geometric=geometric,
            window_deg=window_deg,
        )
    except HexdemError:
        times = []
    return front_shape(positions, arrivals, origin, times, wall_margin=wall_margin_d, window_deg=window_deg)


def run_experiment(
    config: RunConfig, out, log=None, command=None, prepared: RunConfig | None = None, failed_deck=None
) -> ImpactAnalysis:
    """Run ``config`` and publish its result files in ``out`` (see module docstring); ``command``:
    the argument vector that asked for the run, for its provenance (default: this process's; a
    study's worker is handed the study's); ``prepared``: ``config``'s random disc packed already
    (the configuration that strikes it, :func:`prepare_random_packing`), for runs that share one
    packing, which their titles and ``summary.json`` still name as ``config``'s; ``failed_deck``:
    where a failed run keeps its deck, replacing what an earlier try kept there (default: a fresh
    ``hexdem-failed-*`` folder of the temporary directory)."""
    log = log or (lambda message: sys.stderr.write(f"hexdem: {message}\n"))  # one write: a stop never splits the line
    load_in_background(
        "hexdem.analysis.run_maps", "hexdem.analysis.decay_figure", "scipy.spatial"
    )  # the figures, while it runs
    with staged_directory(out, STAGING_PREFIX) as staging:
        try:
            start, provenance = time.perf_counter(), started_provenance(command)
            if prepared is None:
                prepared = prepare_random_packing(config, staging / "preparation", log)
            model = build_model(prepared)
            settings = run_settings(prepared, model)
            check_dump_space(prepared, model, settings, Path(out))
            analysis = simulate_model(prepared, model, settings, staging / "deck", log)
            write_results(config, analysis, staging, time.perf_counter() - start, provenance(), log)
            raise_if_stopped()  # a stopped run is never published, even one whose stop was swallowed
        except HexdemError as exc:
            kept = _keep_failed_deck(staging / "deck", failed_deck)
            if kept is None:
                raise
            raise type(exc)(str(exc).replace(str(staging / "deck"), str(kept))) from None
        except OSError as exc:
            if exc.errno != errno.ENOSPC:
                raise
            raise HexdemError(
                f"no space left on the device of {out} while writing the run's files; nothing was "
                "kept: free some space or choose another --out"
            ) from None
    log(f"energy drift {analysis.results.energy_drift:.2e}; results in {out}")
    for name in run_warnings(analysis.results.far_wall_reached):
        log(f"warning: {RUN_WARNINGS[name]}")
    return analysis


def run_warnings(far_wall_reached: bool) -> list[str]:
    """The names (:data:`RUN_WARNINGS`) of the warnings of a finished run, from its
    ``far_wall_reached``: a leading wave cut short gives decay figures that depend on the run's
    length rather than on the packing."""
    return [] if far_wall_reached else ["far_wall_not_reached"]


def _keep_failed_deck(deck: Path, where=None) -> Path | None:
    """Move a failed run's deck (inputs and log) out of ``--out``, for inspection, to ``where``
    (what is there is replaced) or into a fresh folder of the system's temporary directory; None
    if the run failed before writing one."""
    if not deck.exists():
        return None
    if where is None:
        kept = Path(tempfile.mkdtemp(prefix=FAILED_PREFIX)) / "deck"
    else:
        kept = Path(where) / "deck"
        shutil.rmtree(where, ignore_errors=True)
        kept.parent.mkdir(parents=True)
    shutil.move(str(deck), kept)
    return kept
