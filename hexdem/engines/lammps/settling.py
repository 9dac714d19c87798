"""Damped settling decks: a packing relaxed under loads by viscous drag until it is at rest.

One deck (rendered from ``lammps_inputs/settle.in``) holds the packing's contacts and walls,
some loads (pushes, gravity), an artificial drag F = −γ v and an adaptive time step, and runs
until the packing is settled: its kinetic energy Σ ½ m v² below a tolerance and, if one is
given, no net force component above another, checked every ``check_every`` steps. It writes
its final state (``settled.data``) and how it ended (``settle.txt``). The disorder ensembles'
preparation (:mod:`hexdem.disorder.preparation`) and the random packing
(:mod:`hexdem.experiments.random_packing`) are such decks.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from hexdem.engines.lammps.deck import DATA_NAME, DECK_NAME, data_file, granular_block, integrator, template
from hexdem.engines.lammps.driver import in_folder, start_lammps
from hexdem.engines.lammps.runner import lammps_failure
from hexdem.errors import RunFailed
from hexdem.model.granular import GranularModel
from hexdem.model.units import SI

#: File in which a settling deck writes its final step, time and kinetic energy.
STATS_NAME = "settle.txt"
#: LAMMPS data file with the settled state.
SETTLED_NAME = "settled.data"


def kinetic_tolerance_j(masses_kg, rms_speed_m_s: float) -> float:
    """The settling criterion on the kinetic energy: Σ ½ m v² below ½ (Σ m) v_rms² [J]."""
    return 0.5 * float(np.sum(masses_kg)) * rms_speed_m_s**2


@dataclass(frozen=True)
class SettlingStage:
    """What one settling deck does. ``name`` and ``purpose`` title the deck; ``walls`` and
    ``loads`` are deck blocks, ``loads_note`` says what the loads are; ``damping_s`` is the
    damping time M/γ (M: the mean bead mass) [s]; ``settled_rms_speed_m_s`` [m/s]
    (:func:`kinetic_tolerance_j`) and ``force_tolerance_n`` [N] (None: no force criterion) say
    when it is settled;
    ``max_step_m`` [m] and ``max_dt_s`` [s] bound the distance a bead moves in a step and the
    step; the check runs every ``check_every`` steps after ``min_steps``, for at most
    ``max_steps`` more."""

    name: str
    purpose: str
    walls: str
    loads: str
    loads_note: str
    damping_s: float
    force_tolerance_n: float | None
    settled_rms_speed_m_s: float
    max_step_m: float
    max_dt_s: float
    check_every: int
    min_steps: int
    max_steps: int


def write_settling_deck(model: GranularModel, stage: SettlingStage, directory) -> Path:
    """Render the deck of ``stage`` for ``model``'s packing (positions, diameters, materials;
    its impact is not part of the deck) into ``directory``; returns the directory."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    masses = model.masses_kg[: len(model.packing)]
    kinetic = repr(kinetic_tolerance_j(masses, stage.settled_rms_speed_m_s))
    condition = f"c_kinetic<{kinetic}"
    note = f"kinetic energy below {kinetic} J (rms bead speed {stage.settled_rms_speed_m_s!r} m/s)"
    force = stage.force_tolerance_n
    if force is not None:
        condition = f"({condition})&&(fmax<{force!r})"
        note += f"\n# and no net force component above {force!r} N"
    text = template("settle.in").substitute(
        stage=stage.name,
        purpose=stage.purpose,
        title=f"{model.packing.shape}, {len(model.packing)} beads",
        loads_note=stage.loads_note,
        granular=granular_block(model, SI),
        integrator=integrator(model),
        walls=stage.walls,
        loads=stage.loads,
        damping_time=repr(stage.damping_s),
        gamma=repr(float(masses.mean()) / stage.damping_s),
        max_step=repr(stage.max_step_m),
        max_dt=repr(stage.max_dt_s),
        first_dt=repr(stage.max_dt_s / 100),
        thermo_every=10 * stage.check_every,
        min_steps=stage.min_steps,
        check_every=stage.check_every,
        max_steps=stage.max_steps,
        settled_condition=condition,
        settled_note=note,
        kinetic_tolerance=kinetic,
        force_tolerance="inf" if force is None else repr(force),
        stats=STATS_NAME,
        output=SETTLED_NAME,
    )
    (directory / DATA_NAME).write_text(data_file(replace(model, impact=replace(model.impact, striker=False)), SI))
    (directory / DECK_NAME).write_text(text)
    return directory


def run_settling_deck(directory) -> None:
    """Run the settling deck in ``directory`` in this process, on this rank alone, as
    ``lmp -in in.hexdem`` would from ``directory`` (its files named there, :func:`in_folder`)."""
    directory = Path(directory)
    text = in_folder((directory / DECK_NAME).read_text(), directory, (DATA_NAME, STATS_NAME, SETTLED_NAME))
    lmp = start_lammps(directory)
    try:
        lmp.commands_string(text)
    except Exception as exc:
        raise lammps_failure(directory, str(exc)) from None
    finally:
        lmp.close()


@dataclass(frozen=True)
class StageResult:
    """How a settling deck ended: ``steps`` taken, simulated ``time_s`` [s], final
    ``kinetic_energy_j`` [J] and largest net force component ``max_force_n`` [N], against
    the criteria ``tolerance_j`` and ``force_tolerance_n``."""

    steps: int
    time_s: float
    kinetic_energy_j: float
    tolerance_j: float
    max_force_n: float
    force_tolerance_n: float

    @property
    def settled(self) -> bool:
        return self.kinetic_energy_j < self.tolerance_j and self.max_force_n < self.force_tolerance_n


def read_stage(directory) -> StageResult:
    """The :class:`StageResult` a finished settling deck wrote into ``directory``."""
    path = Path(directory) / STATS_NAME
    try:
        words = path.read_text().split()
        values = dict(zip(words[::2], words[1::2]))
        return StageResult(
            int(values["steps"]),
            float(values["time_s"]),
            float(values["kinetic_energy_j"]),
            float(values["tolerance_j"]),
            float(values["max_force_n"]),
            float(values["force_tolerance_n"]),
        )
    except (OSError, KeyError, ValueError):
        raise RunFailed(f"{path} is missing or unreadable: the settling deck did not finish") from None


@dataclass(frozen=True)
class DataFileState:
    """Bodies of a LAMMPS data file, ordered by atom id: ``diameters_m`` (N,),
    ``positions_m`` (N, 2), ``velocities_m_s`` (N, 2) (zero when the file has none)."""

    diameters_m: np.ndarray
    positions_m: np.ndarray
    velocities_m_s: np.ndarray


def _section(lines: list[str], name: str, count: int) -> np.ndarray | None:
    starts = [i for i, line in enumerate(lines) if line.split("#")[0].strip() == name]
    if not starts:
        return None
    rows = [line.split() for line in lines[starts[0] + 1 :] if line.strip()][:count]
    table = np.array(rows, dtype=float)
    return table[np.argsort(table[:, 0])]


def read_data_file(path) -> DataFileState:
    """Read an ``atom_style sphere`` data file (as written by ``write_data``), SI units."""
    path = Path(path)
    try:
        lines = path.read_text().splitlines()
        count = next(int(line.split()[0]) for line in lines if line.strip().endswith(" atoms"))
        atoms = _section(lines, "Atoms", count)
        velocities = _section(lines, "Velocities", count)
        if atoms is None or len(atoms) != count or (velocities is not None and len(velocities) != count):
            raise ValueError
    except (OSError, StopIteration, ValueError):
        raise RunFailed(f"{path} is not a complete LAMMPS data file") from None
    return DataFileState(
        diameters_m=atoms[:, 2],
        positions_m=atoms[:, 4:6],
        velocities_m_s=np.zeros((count, 2)) if velocities is None else velocities[:, 1:3],
    )
