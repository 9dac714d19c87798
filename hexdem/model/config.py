"""Parameters of one impact simulation, their defaults and validation, and TOML loading.

Defaults are the paper's experiment (Sec. II): a hexagon with 11 steel-316 beads per edge
(d = 19.05 mm), delrin-lined walls touching the packing, V0 = 0.4 m/s given to the centre
bead of an edge, 0° strike, ideal lattice. Every field can be set from a TOML file whose
keys are the field names. ``v0``, ``dt`` and ``duration`` are in the run's ``units``: SI
(m/s, s) or the paper's nondimensional A = d = M = 1.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from dataclasses import dataclass

from hexdem.common.checks import positive_int
from hexdem.common.io import read_toml
from hexdem.common.machine import available_memory_bytes
from hexdem.common.typecheck import check_fields
from hexdem.errors import HexdemError
from hexdem.model.contact_law import Friction
from hexdem.model.dissipation import damping_coefficient, lammps_tsuji_coefficient
from hexdem.model.granular import GranularModel, Impact, RunSettings
from hexdem.model.hertz import contact_time
from hexdem.model.impacts import ImpactSpec, ImpactTable, cut_holes, impact_specs, resolve_impacts, struck_site
from hexdem.model.initial_state import read_initial_state
from hexdem.model.lattice import Lattice, without_hole, without_sites
from hexdem.model.lines import LineTable, with_lines
from hexdem.model.packing_builders import PLACED_SHAPES, SHAPES, BuiltPacking, build_packing
from hexdem.model.materials import (PAPER_DIAMETER_M, Material, MaterialTable, custom_materials, hertz_coefficient,
                                     hertz_stiffness, material)
from hexdem.model.precompression import hole_force, precompressed_lattice
from hexdem.model.regions import RegionTable, assign_materials
from hexdem.model.sensors import sensor_beads
from hexdem.model.timescale import (crossing_time_s, fastest_approach_m_s, impact_contact_time_s, sized_bodies,
                                    striker_launch_s)
from hexdem.model.units import SI, UnitSystem, nondimensional

IMPACTS = ("velocity", "striker")
UNITS = ("si", "nondimensional")
ENGINES = ("lammps", "reference")
#: Default time step: this many steps per two-bead Hertz contact at V0 (5.1e-7 s at 0.4 m/s).
#: Chosen by accuracy (benchmarks/bench_accuracy.py): velocity Verlet's errors fall as dt²,
#: about 0.7/N² relative in peak speed for N steps per contact, so 140 steps keep the peaks
#: within 1e-4 (measured: 3.7e-5) and the arrival times within 0.05 µs of the converged answer,
#: at the experiment's 0.4 m/s and over the sweep's V0 = 0.01–0.30 alike (the Hertz lattice is
#: scale-invariant in units of the contact time).
STEPS_PER_CONTACT = 140
#: Samples per contact time, whatever the step (every 3.6 µs at 0.4 m/s; its error with the step's
#: stays inside the targets: ``convergence.sampling_error``); default ``dump_every``: STEPS_PER_CONTACT / this.
SAMPLES_PER_CONTACT = 20
#: A time step must resolve the Hertz contact at V0 with at least this many steps (energy drift
#: grows as dt²: about 4e-5 at 140 steps, 1e-3 at about 30).
MIN_STEPS_PER_CONTACT = 20
#: The analysis needs at least this many samples per contact time at V0, and this many in all.
MIN_SAMPLES_PER_CONTACT = 4
MIN_SAMPLES = 10
#: Memory a run needs on each process, a conservative bound: a fixed part (Python, NumPy, SciPy,
#: numba, LAMMPS and the plotting libraries loaded) and a part per bead (LAMMPS's atoms and
#: neighbour lists, the lattice, the tracker's state). benchmarks/bench_scale.py measured
#: 267 MB at 331 beads and 313 MB at 29,701 (about 2 kB per bead).
MEMORY_BASE_BYTES = 400e6
MEMORY_PER_BEAD_BYTES = 8e3


@dataclass(frozen=True)
class RunConfig:
    """One simulation: every key a configuration file may set, each checked against its declared
    type (:mod:`hexdem.common.typecheck`) and its meaning in
    :data:`~hexdem.model.config_keys.KEY_DESCRIPTIONS`. Lengths in m; ``v0``, ``dt``, ``duration``
    in ``units``. ``dt = None`` takes the contact time (:meth:`contact_time_s`) over
    ``steps_per_contact``, shortened so that the default sampling interval, 1/20 of the contact
    time, is whole steps; ``duration = None`` follows the pulse layer by layer from the struck
    bead to the far wall, each layer for the contact time of its quickest material, and a soft
    striker's longer contact (:func:`~hexdem.model.timescale.crossing_time_s`; the pulse resides
    less than that on each layer: 0.82 ms are needed, 1.43 ms are run for the default experiment).
    """

    shape: str = "hexagon"
    edge_beads: int = 11
    long_edge: int = 91
    short_edge: int = 46
    radius_beads: int = 100
    depth_beads: int | None = None
    sites: tuple[tuple[int, int], ...] = ()
    sites_file: str | None = None
    site_walls_deg: tuple[float, ...] = ()
    vacancies: tuple[tuple[int, int], ...] = ()
    diameter_m: float = PAPER_DIAMETER_M
    bead_material: str = "steel316"
    wall_material: str = "delrin"
    materials: dict[str, MaterialTable] | tuple[str, ...] = dataclasses.field(default_factory=dict)
    regions: tuple[RegionTable, ...] = ()
    striker_material: str | None = None
    striker_diameter_m: float | None = None
    impacts: tuple[ImpactTable, ...] = ()
    lines: tuple[LineTable, ...] = ()
    movie: bool = False
    units: str = "si"
    v0: float = 0.4
    strike_angle_deg: float = 0.0
    impact: str = "velocity"
    dt: float | None = None
    steps_per_contact: int = STEPS_PER_CONTACT
    duration: float | None = None
    dump_every: int | None = None
    ranks: int = 1
    engine: str = "lammps"
    dump: bool = False
    restitution: float = 1.0
    wall_restitution: float | None = None
    friction: float = 0.0
    wall_friction: float | None = None
    rolling_friction: float = 0.0
    precompression_n: float = 0.0
    initial_state_file: str | None = None
    sensors: tuple[str | int, ...] = ()
    sensor_rate_hz: float = 500e3
    sensor_mass_factor: float = 1.0
    launcher: str | None = None
    rows: int = 15
    columns: int = 15
    interstitial_diameter_m: float | None = None
    interstitial_material: str | None = None
    beads: int = 20
    angle_deg: float = 0.0
    diameters_m: tuple[float, ...] = ()
    packing_file: str | None = None
    walls: str = "none"
    struck_bead: int = 0

    def __post_init__(self):
        check_fields(self)
        for name, allowed in (("shape", SHAPES), ("impact", IMPACTS), ("units", UNITS), ("engine", ENGINES)):
            if getattr(self, name) not in allowed:
                raise HexdemError(f"unknown {name} {getattr(self, name)!r}; use one of: {', '.join(allowed)}")
        for name in ("dump_every", "ranks"):
            if getattr(self, name) is not None:
                positive_int(name, getattr(self, name))
        if positive_int("steps_per_contact", self.steps_per_contact) < MIN_STEPS_PER_CONTACT:
            raise HexdemError(f"steps_per_contact must be at least {MIN_STEPS_PER_CONTACT} (the Hertz contact "
                              f"needs them), got {self.steps_per_contact}")
        for name in ("sensors", "sites", "site_walls_deg", "vacancies", "regions", "impacts", "lines", "diameters_m"):
            object.__setattr__(self, name, tuple(tuple(v) if isinstance(v, list) else v for v in getattr(self, name)))
        if not self.sensor_rate_hz > 0:
            raise HexdemError(f"sensor_rate_hz must be > 0, got {self.sensor_rate_hz!r}")
        if not self.precompression_n >= 0:
            raise HexdemError(f"precompression_n must be a force >= 0 N, got {self.precompression_n!r}")
        if self.launcher is not None and not self.launcher.split():
            raise HexdemError(f"launcher must be a command such as \"mpiexec -f hosts\", got {self.launcher!r}")
        for name in ("dt", "duration"):
            value = getattr(self, name)
            if value is not None and not value > 0:
                raise HexdemError(f"{name} must be a positive number of {self.units} time units, got {value!r}")
        self._check_size()
        self._check_sampling(self.settings(self.model()))

    def n_beads(self) -> int:
        """Beads of the packing: 3N(N − 1) + 1 for a hexagon with N per edge, S(3S − 1)/2 for a
        half-hexagon with short edges of S (both counted without building them, less the
        vacancies), any other packing's counted on its lattice."""
        if self.shape == "hexagon":
            return 3 * self.edge_beads * (self.edge_beads - 1) + 1 - len(self.vacancies)
        if self.shape == "half-hexagon":
            return self.short_edge * (3 * self.short_edge - 1) // 2 - len(self.vacancies)
        return len(self.lattice())

    def memory_estimate_bytes(self) -> float:
        """Peak memory of the run on each of its processes [bytes] (see MEMORY_PER_BEAD_BYTES)."""
        return MEMORY_BASE_BYTES + MEMORY_PER_BEAD_BYTES * self.n_beads()

    def _check_size(self) -> None:
        # the packings counted without building them (n_beads) need sizes the count holds for;
        # the others are built, and their builders word any error
        counted = {"hexagon": (self.edge_beads,), "half-hexagon": (self.short_edge, self.long_edge)}
        if not all(n >= 2 for n in counted.get(self.shape, ())):
            return  # the lattice builder words the error
        needed = self.memory_estimate_bytes() * (self.ranks if self.engine == "lammps" else 1)
        available = available_memory_bytes()
        if needed > available:
            raise HexdemError(f"{self.shape} of {self.n_beads():,} beads needs about {needed / 1e9:.3g} GB of memory "
                              f"({self.ranks if self.engine == 'lammps' else 1} process(es)); this machine has "
                              f"{available / 1e9:.3g} GB available")

    def _check_sampling(self, settings: RunSettings) -> None:
        """Refuse a time step that does not resolve the Hertz contact, or too few samples."""
        contact_s = settings.contact_time_s
        scale = self.unit_system.time_s
        if settings.dt_s > contact_s / MIN_STEPS_PER_CONTACT:
            raise HexdemError(f"time step {settings.dt_s / scale:.3g} is not small against the Hertz contact time "
                              f"{contact_s / scale:.3g} at V0 (in {self.units} units): use dt <= "
                              f"{contact_s / scale / MIN_STEPS_PER_CONTACT:.3g}, or leave dt at its default")
        interval_s = settings.dt_s * settings.dump_every
        if settings.n_samples < MIN_SAMPLES or interval_s > contact_s / MIN_SAMPLES_PER_CONTACT:
            raise HexdemError(f"too few samples to analyse: {settings.n_samples} samples, one every "
                              f"{interval_s / scale:.3g} (contact time {contact_s / scale:.3g}); need at least "
                              f"{MIN_SAMPLES} and {MIN_SAMPLES_PER_CONTACT} per contact time: lower dump_every "
                              "or lengthen duration")

    @classmethod
    def from_toml(cls, path) -> "RunConfig":
        """Read a TOML file whose keys are :class:`RunConfig` field names; a relative ``packing_file``
        is read from the TOML file's folder."""
        data = read_toml(path)
        if isinstance(data.get("packing_file"), str) and not Path(data["packing_file"]).is_absolute():
            data["packing_file"] = str(Path(path).parent / data["packing_file"])
        return cls.from_dict(data, source=str(path))

    @classmethod
    def from_dict(cls, data: dict, source: str = "config") -> "RunConfig":
        known = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(data) - known)
        if unknown:
            raise HexdemError(f"{source}: unknown parameter(s) {', '.join(unknown)}; known: {', '.join(sorted(known))}")
        return cls(**data)

    def replace(self, **changes) -> "RunConfig":
        return dataclasses.replace(self, **changes)

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)

    def material(self, name: str) -> Material:
        """The material called ``name``: a preset or one of this configuration's ``materials``."""
        return material(name, custom_materials(self.materials if isinstance(self.materials, dict) else {}))

    @property
    def unit_system(self) -> UnitSystem:
        """The units of ``v0``, ``dt``, ``duration`` and of every result of this run."""
        return SI if self.units == "si" else nondimensional(self.diameter_m, self.material(self.bead_material))

    def impact_specs(self) -> list[ImpactSpec]:
        """The configured impacts, the run's values filled in (:func:`~hexdem.model.impacts.impact_specs`)."""
        return impact_specs(self.impacts, self.v0, self.strike_angle_deg, self.impact, self.striker_material,
                            self.striker_diameter_m)

    def packing(self) -> BuiltPacking:
        """The ``shape``'s packing (:func:`~hexdem.model.packing_builders.build_packing`) less the
        ``vacancies``, struck at the first impact's site, with the extra observation ``lines``,
        and the material regions of its builder."""
        built = build_packing(self, struck_site(self.impact_specs()))
        lattice = without_hole(built.lattice) if self.impacts else built.lattice  # each impact cuts its own
        lattice = without_sites(lattice, self.vacancies) if self.vacancies else lattice
        return BuiltPacking(with_lines(lattice, self.lines) if self.lines else lattice, built.regions)

    def lattice(self) -> Lattice:
        """The packing of :meth:`packing`."""
        return self.packing().lattice

    def model(self) -> GranularModel:
        """The SI :class:`GranularModel` this configuration describes."""
        if not self.v0 > 0:
            raise HexdemError(f"v0 must be > 0 (the impact moves into the packing), got {self.v0!r}")
        wall = None if self.wall_material == "none" else self.material(self.wall_material)
        wall_restitution = self.restitution if self.wall_restitution is None else self.wall_restitution
        for alpha in {damping_coefficient(self.restitution), damping_coefficient(wall_restitution)} - {0.0}:
            lammps_tsuji_coefficient(alpha)
        bead, held = self.material(self.bead_material), (0.0, 0.0)
        built = self.packing()
        lattice, extra = assign_materials(built.lattice, built.regions + self.regions, bead, self.material)
        if self.precompression_n > 0:
            if extra:
                raise HexdemError("precompression is built for a packing of one material; drop the regions")
            if wall is None:
                raise HexdemError("a precompressed packing needs walls to hold it (wall_material = \"none\")")
            if self.shape == "half-disc":
                raise HexdemError("a precompressed packing needs walls all round; the half-disc's arc is free")
            if self.shape in ("disc", "sites") + PLACED_SHAPES:
                raise HexdemError(f"precompression is built for flat-walled basins (hexagon, half-hexagon, triangle, "
                                  f"parallelogram), not shape = {self.shape!r}")
            coefficient = float(hertz_coefficient(self.diameter_m, bead))
            lattice = precompressed_lattice(lattice, self.precompression_n, coefficient, hertz_stiffness(bead, wall))
            held = tuple(float(f) for f in hole_force(lattice, self.precompression_n))
        impacts = self._impacts(lattice)
        if self.impacts:
            holed, opened = cut_holes(lattice, impacts)
            if self.precompression_n > 0:
                if opened - {lattice.struck}:
                    raise HexdemError("a precompressed packing holds only the first impact's bead in a hole of its "
                                      "wall; strike the other beads inside the packing")
                held = held if lattice.struck in opened else (0.0, 0.0)
            lattice = holed
        state = None if self.initial_state_file is None else read_initial_state(self.initial_state_file, lattice)
        return GranularModel(lattice, impacts[0], bead, wall, self.restitution, wall_restitution, held,
                             tuple(self.sensor_beads(lattice).values()), self.sensor_mass_factor, extra,
                             tuple(impacts[1:]), Friction.of(self.friction, self.wall_friction, self.rolling_friction),
                             state)

    def _impacts(self, lattice: Lattice) -> list[Impact]:
        """The model's impacts: the paper's single one on the struck bead, or those of ``impacts``."""
        if not self.impacts:
            striker = None if self.striker_material is None else self.material(self.striker_material)
            return [Impact(self.v0 * self.unit_system.velocity_m_s, self.strike_angle_deg, self.impact == "striker",
                           None, striker, self.striker_diameter_m)]
        return resolve_impacts(self.impact_specs(), lattice, self.unit_system.velocity_m_s, self.material)

    def sensor_beads(self, lattice: Lattice) -> dict[str, int]:
        """{label: bead index} of the ``sensors`` on ``lattice`` (:func:`~hexdem.model.sensors.sensor_beads`)."""
        return sensor_beads(self.sensors, lattice)

    def contact_time_s(self, model: GranularModel | None = None) -> float:
        """The natural time scale of the impacts [s] (:func:`~hexdem.model.timescale.impact_contact_time_s`):
        the shortest two-body Hertz contact time at an impact's V0 or at the initial state's fastest
        approach (read on ``model``, built if not given), or, if shorter, half the period of two
        beads on the linearized precompressed contact."""
        strikers = [(spec.v0 * self.unit_system.velocity_m_s,
                     (self.material(spec.striker_material or self.bead_material), spec.striker_diameter_m or self.diameter_m)
                     if spec.striker and (spec.striker_material is not None or spec.striker_diameter_m is not None)
                     else None) for spec in self.impact_specs()]
        if model is None and (self.initial_state_file is not None or self.shape in PLACED_SHAPES):
            model = self.model()
        if self.initial_state_file is not None:
            fastest = fastest_approach_m_s(model)
            strikers += [(fastest, striker) for _, striker in strikers]
        sized = () if self.shape not in PLACED_SHAPES else sized_bodies(model)
        return impact_contact_time_s(self.material(self.bead_material), self.diameter_m,
                                     [self.material(r["material"]) for r in self.regions], strikers,
                                     self.precompression_n, sized)

    def _rebound_time_s(self, model: GranularModel) -> float:
        """The default duration [s] when nothing lies ahead of the struck beads (a single bead, a
        row struck along its normal): the longest of each struck bead's head-on Hertz contacts
        with the walls at its impact's speed (mass m against a rigid body, A = k_n sqrt(r)), plus one
        contact time, so that the run holds the whole rebound and the bead's flight after it."""
        walls = [0.0]
        if model.walls:
            masses, radii = model.masses_kg, model.lattice.radii_m
            for bead, impact in zip(model.struck_beads, model.impacts):
                coefficient = float(model.wall_stiffness_pa([bead])[0]) * math.sqrt(radii[bead])
                walls.append(float(contact_time(masses[bead], coefficient, impact.speed_m_s)))
        return self.contact_time_s(model) + max(walls)

    def _step_and_sampling(self, contact_s: float) -> tuple[float, int]:
        """(dt [s], steps between samples): ``dt`` or the contact time ``contact_s`` over ``steps_per_contact``,
        and ``dump_every`` or the steps of one default sampling interval (1/20 of the contact
        time), the default step shortened so that this interval is a whole number of steps."""
        interval_s = contact_s / SAMPLES_PER_CONTACT
        if self.dt is not None:
            dt_s = self.dt * self.unit_system.time_s
            return dt_s, self.dump_every or max(1, round(interval_s / dt_s))
        if self.dump_every is not None:
            return contact_s / self.steps_per_contact, self.dump_every
        every = math.ceil(self.steps_per_contact / SAMPLES_PER_CONTACT)
        return interval_s / every, every

    def settings(self, model: GranularModel | None = None) -> RunSettings:
        """Time step, step count and dump interval in SI, with the defaults resolved. With sensors,
        the time step is shortened (at most by one sample's worth) so that a sensor sample is a
        whole number of analysis samples of ``dump_every`` steps."""
        model = model or self.model()
        scale = self.unit_system.time_s
        contact_s = self.contact_time_s(model)
        dt_s, every = self._step_and_sampling(contact_s)
        if self.duration is not None:
            duration_s = self.duration * scale
        else:
            crossing_s = crossing_time_s(model, contact_s if self.precompression_n > 0 else None)
            duration_s = crossing_s + striker_launch_s(model) if crossing_s > 0 else self._rebound_time_s(model)
        sensor_every = 0
        if self.sensors:
            samples = math.ceil(1.0 / self.sensor_rate_hz / (dt_s * every) - 1e-9)
            sensor_every = samples * every
            dt_s = 1.0 / self.sensor_rate_hz / sensor_every
        n_steps = max(1, round(duration_s / dt_s))
        return RunSettings(dt_s=dt_s, n_steps=n_steps, dump_every=every, units=self.unit_system,
                           sensor_every=sensor_every, contact_time_s=contact_s)
