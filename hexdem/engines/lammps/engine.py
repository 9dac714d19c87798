"""LAMMPS as a hexdem engine (an ASE-style calculator): model in, :class:`Trajectory` out."""

from __future__ import annotations

from dataclasses import dataclass

from hexdem.analysis.dump import read_dump
from hexdem.analysis.trajectory import Trajectory
from hexdem.engines.lammps.deck import Deck, write_deck
from hexdem.engines.lammps.runner import RunInfo, run_deck
from hexdem.model.granular import GranularModel, RunSettings


@dataclass(frozen=True)
class LammpsEngine:
    """Run a model in LAMMPS on ``ranks`` MPI ranks (1: in-process; more: ``mpiexec``)."""

    ranks: int = 1
    name = "lammps"

    def run(self, model: GranularModel, settings: RunSettings, directory) -> Trajectory:
        """Render the deck into ``directory``, run it, and read its dump back in SI."""
        deck = write_deck(model, settings, directory)
        return read_trajectory(deck, run_deck(deck, self.ranks))


def read_trajectory(deck: Deck, info: RunInfo) -> Trajectory:
    """The finished run of ``deck`` (however it was run, see ``info``) as a SI :class:`Trajectory`."""
    settings = deck.settings
    units = settings.units
    record = read_dump(deck.dump_path, settings.dt_s / units.time_s, settings.n_samples).results
    return Trajectory(times_s=record.times * units.time_s,
                      velocities_m_s=record.velocities * units.velocity_m_s,
                      displacements_m=record.displacements * units.length_m,
                      engine={"name": LammpsEngine.name, "version": info.lammps_version, "ranks": info.ranks,
                              "wall_time_s": info.wall_time_s, "deck": str(deck.input_path)})
