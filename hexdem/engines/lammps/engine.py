"""LAMMPS as a hexdem engine (an ASE-style calculator): model in, samples out to an observer."""

from __future__ import annotations

from dataclasses import dataclass

from hexdem.engines.lammps.deck import Deck, write_deck
from hexdem.engines.lammps.driver import run_streaming
from hexdem.engines.lammps.tsuji_check import check_tsuji_damping
from hexdem.engines.sampling import Observer
from hexdem.model.granular import GranularModel, RunSettings


@dataclass(frozen=True)
class LammpsEngine:
    """Run a model in LAMMPS through the ``lammps`` module, streaming its samples.

    ``dump``: also write the deck's full trajectory dump; ``gravity_m_s2``: uniform in-plane
    gravity (gx, gy) [m/s²] in the deck (the tilted set-up of Sec. VI-A), or None.
    """

    dump: bool = False
    gravity_m_s2: tuple[float, float] | None = None
    name = "lammps"

    def run(
        self,
        model: GranularModel,
        settings: RunSettings,
        directory,
        on_sample: Observer,
        comm=None,
        show_progress: bool = True,
    ) -> dict:
        """Render the deck into ``directory`` (on rank 0 of ``comm``) and run it on every rank of
        ``comm`` (None: this process alone), calling ``on_sample`` with each rank's samples.
        Returns a description of the run (name, version, ranks, wall_time_s, deck). A damped model's
        run starts with a check that LAMMPS gives its restitutions
        (:func:`~hexdem.engines.lammps.tsuji_check.check_tsuji_damping`)."""
        for alpha in {model.pair_damping, model.wall_damping if model.walls else 0.0} - {0.0}:
            check_tsuji_damping(alpha)
        if comm is None or comm.Get_rank() == 0:
            deck = write_deck(model, settings, directory, self.gravity_m_s2)
        if comm is not None:
            comm.Barrier()
        deck = Deck(directory, settings, model.n_bodies)
        info = run_streaming(deck, on_sample, comm, self.dump, show_progress, spins=model.laws.tangential)
        return {
            "name": self.name,
            "version": info.lammps_version,
            "ranks": info.ranks,
            "wall_time_s": info.wall_time_s,
            "deck": str(deck.input_path),
        }
