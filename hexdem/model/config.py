"""Parameters of one impact simulation, their defaults and validation, and TOML loading.

:class:`RunConfig` is the schema: it holds the keys and checks each one. It builds nothing:
:mod:`hexdem.model.model_builder` makes the packing and the model it describes, and
:mod:`hexdem.model.run_settings` the time step and the run's length.

Defaults are the paper's experiment (Sec. II): a hexagon with 11 steel-316 beads per edge
(d = 19.05 mm), delrin-lined walls touching the packing, V0 = 0.4 m/s given to the centre
bead of an edge, 0° strike, ideal lattice. Every field can be set from a TOML file whose
keys are the field names. ``v0``, ``dt`` and ``duration`` are in the run's ``units``: SI
(m/s, s) or the paper's nondimensional A = d = M = 1.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
from dataclasses import dataclass
from pathlib import Path

from hexdem.common.checks import positive_int
from hexdem.common.io import read_toml
from hexdem.common.machine import available_memory_bytes
from hexdem.common.typecheck import check_fields
from hexdem.errors import HexdemError
from hexdem.model.contact_law import Friction
from hexdem.model.dissipation import damping_coefficient, lammps_tsuji_coefficient
from hexdem.model.impacts import ImpactSpec, ImpactTable, impact_specs
from hexdem.model.lines import LineTable
from hexdem.model.materials import PAPER_DIAMETER_M, Material, MaterialTable, custom_materials, material
from hexdem.model.packing_builders import SHAPE_KEYS, SHAPES, IntruderTable, check_shape_keys
from hexdem.model.random_disc import DENSE_FRACTION, check_random_disc
from hexdem.model.regions import RegionTable
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
#: A time step must resolve the Hertz contact at V0 with at least this many steps (energy drift
#: grows as dt²: about 4e-5 at 140 steps, 1e-3 at about 30).
MIN_STEPS_PER_CONTACT = 20
#: Memory a run needs on each process, a conservative bound: a fixed part (Python, NumPy, SciPy,
#: numba, LAMMPS and the plotting libraries loaded), a part per bead that every process holds (the
#: packing and model, and rank 0's final results) and a part per bead of its own (LAMMPS's atoms
#: and neighbour lists, the tracker's rows), its share of the beads. Each part lies above the
#: peaks ``benchmarks/bench_scale.py`` measures (docs/validation/benchmarks.md, *At scale*).
MEMORY_BASE_BYTES = 400e6
MEMORY_PER_BEAD_BYTES = 1e3
MEMORY_PER_OWN_BEAD_BYTES = 8e3


def read_config_table(path) -> dict:
    """The table of run-config keys in the TOML file at ``path``, a relative ``packing_file`` made
    relative to the file's folder, as every command that reads a configuration file reads it."""
    data = read_toml(path)
    if isinstance(data.get("packing_file"), str) and not Path(data["packing_file"]).is_absolute():
        data["packing_file"] = str(Path(path).parent / data["packing_file"])
    return data


@dataclass(frozen=True)
class RunConfig:
    """One simulation: every key a configuration file may set, each checked against its declared
    type (:mod:`hexdem.common.typecheck`) and its meaning in
    :data:`~hexdem.model.config_keys.KEY_DESCRIPTIONS`. Lengths in m; ``v0``, ``dt``, ``duration``
    in ``units``. ``given``: the keys the user wrote (:meth:`from_dict`, :meth:`override`), each
    set whatever its value (:meth:`set_keys`). ``dt = None`` takes the contact time
    (:func:`~hexdem.model.run_settings.contact_time_s`) over
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
    materials: dict[str, MaterialTable] = dataclasses.field(default_factory=dict)
    regions: tuple[RegionTable, ...] = ()
    striker_material: str | None = None
    striker_diameter_m: float | None = None
    impacts: tuple[ImpactTable, ...] = ()
    lines: tuple[LineTable, ...] = ()
    movie: bool = False
    units: str = "si"
    v0: float = 0.4
    strike_angle_deg: float | None = None
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
    bead_materials: tuple[str, ...] = ()
    intruders: tuple[IntruderTable, ...] = ()
    packing_file: str | None = None
    walls: str = "none"
    struck_bead: int = 0
    radius_m: float = 0.1
    diameter_spread: float = 0.15
    seed: int = 0
    given: dataclasses.InitVar[frozenset[str]] = frozenset()

    def __post_init__(self, given):
        object.__setattr__(self, "given", frozenset(given))
        if isinstance(self.materials, (list, tuple)):
            raise HexdemError(
                "materials is a table of this configuration's own materials; a chain's material "
                'per bead goes in bead_materials = ["steel316", "brass", ...]'
            )
        check_fields(self)
        for name, allowed in (("shape", SHAPES), ("impact", IMPACTS), ("units", UNITS), ("engine", ENGINES)):
            if getattr(self, name) not in allowed:
                raise HexdemError(f"unknown {name} {getattr(self, name)!r}; use one of: {', '.join(allowed)}")
        for name in ("dump_every", "ranks"):
            if getattr(self, name) is not None:
                positive_int(name, getattr(self, name))
        if positive_int("steps_per_contact", self.steps_per_contact) < MIN_STEPS_PER_CONTACT:
            raise HexdemError(
                f"steps_per_contact must be at least {MIN_STEPS_PER_CONTACT} (the Hertz contact "
                f"needs them), got {self.steps_per_contact}"
            )
        for name in (
            "sensors",
            "sites",
            "site_walls_deg",
            "vacancies",
            "regions",
            "impacts",
            "lines",
            "diameters_m",
            "bead_materials",
            "intruders",
        ):
            object.__setattr__(self, name, tuple(tuple(v) if isinstance(v, list) else v for v in getattr(self, name)))
        if not self.sensor_rate_hz > 0:
            raise HexdemError(f"sensor_rate_hz must be > 0, got {self.sensor_rate_hz!r}")
        if not self.precompression_n >= 0:
            raise HexdemError(f"precompression_n must be a force >= 0 N, got {self.precompression_n!r}")
        if self.launcher is not None and not self.launcher.split():
            raise HexdemError(f'launcher must be a command such as "mpiexec -f hosts", got {self.launcher!r}')
        for name in ("dt", "duration"):
            value = getattr(self, name)
            if value is not None and not value > 0:
                raise HexdemError(f"{name} must be a positive number of {self.units} time units, got {value!r}")
        if not self.v0 > 0:
            raise HexdemError(f"v0 must be > 0 (the impact moves into the packing), got {self.v0!r}")
        check_shape_keys(self)
        if self.strike_angle_deg is not None and math.cos(math.radians(self.strike_angle_deg - self.inward_deg)) <= 0:
            raise HexdemError(
                f"strike angle {self.strike_angle_deg}° does not point into the packing, which lies at "
                f"{self.inward_deg:g}° from its struck bead: use an angle within 90° of it, or leave "
                "strike_angle_deg out"
            )
        for alpha in {damping_coefficient(self.restitution), damping_coefficient(self.effective_wall_restitution)}:
            if alpha:
                lammps_tsuji_coefficient(alpha)
        self._check_materials()
        if self.shape == "random":
            check_random_disc(self.radius_m, self.diameter_m, self.diameter_spread, self.seed)
        self._check_size()
        Friction.of(self.friction, self.wall_friction, self.rolling_friction)  # refuses a bad coefficient

    def n_beads(self) -> int | None:
        """Beads of the packing counted without building it, less the vacancies: 3N(N − 1) + 1
        for a hexagon with N per edge, S(3S − 1)/2 for a half-hexagon with short edges of S;
        None for the other shapes (count the built lattice,
        :func:`~hexdem.model.model_builder.build_packing`)."""
        if self.shape == "hexagon":
            return 3 * self.edge_beads * (self.edge_beads - 1) + 1 - len(self.vacancies)
        if self.shape == "half-hexagon":
            return self.short_edge * (3 * self.short_edge - 1) // 2 - len(self.vacancies)
        return None

    def _check_materials(self) -> None:
        """Every material the keys name must be a preset or one of ``materials`` (each table
        complete); a chain's ``bead_materials`` and ``intruders`` and the ``regions`` name theirs the
        same way."""
        names = [
            self.bead_material,
            self.striker_material,
            self.interstitial_material,
            *(spec.striker_material for spec in self.impact_specs()),
            *(region["material"] for region in self.regions if isinstance(region, dict) and "material" in region),
            *(name for name in self.bead_materials if name),
            *(intruder.get("material") for intruder in self.intruders),
        ]
        for name in dict.fromkeys(names):
            if isinstance(name, str):
                self.material(name)
        if self.wall_material != "none":
            self.material(self.wall_material)

    @property
    def processes(self) -> int:
        """The processes the run takes: ``ranks`` for LAMMPS, one for the reference engine."""
        return self.ranks if self.engine == "lammps" else 1

    def max_beads(self) -> int:
        """The most beads the packing can hold, counted without building it (:meth:`n_beads` where
        it counts): rows × columns of a square, plus the interstitials of a centered square; a
        chain's beads; the sites listed; the triangular lattice's sites within the disc's area
        (2π/√3 (R + 1)² for a radius of R d, half for a half-disc); a file's lines, at least
        4 bytes each (``0,0``) for sites and 6 (``0,0,1``) for a packing; a random disc's share
        of its area, :data:`~hexdem.model.random_disc.DENSE_FRACTION`, over its smallest bead's."""

        def lines(path, shortest):
            return Path(path).stat().st_size // shortest if path and Path(path).is_file() else 0

        counted = self.n_beads()
        if counted is not None:
            return counted
        disc_sites = 2 * math.pi / math.sqrt(3) * (self.radius_beads + 1) ** 2
        smallest = self.diameter_m * (1 - self.diameter_spread)
        return int(
            {
                "triangle": lambda: self.edge_beads * (self.edge_beads + 1) / 2,
                "parallelogram": lambda: self.edge_beads * (self.depth_beads or self.edge_beads),
                "half-disc": lambda: disc_sites / 2,
                "disc": lambda: disc_sites,
                "sites": lambda: len(self.sites) + lines(self.sites_file, 4),
                "square": lambda: self.rows * self.columns,
                "centered-square": lambda: self.rows * self.columns + (self.rows - 1) * (self.columns - 1),
                "chain": lambda: self.beads,
                "packing": lambda: lines(self.packing_file, 6),
                "random": lambda: DENSE_FRACTION * (2 * self.radius_m / smallest) ** 2 + 2,
            }[self.shape]()
        )

    def memory_estimate_bytes(self) -> float:
        """Peak memory of the run on each of its processes [bytes] (see MEMORY_PER_BEAD_BYTES and
        MEMORY_PER_OWN_BEAD_BYTES), for the most beads its packing can hold (:meth:`max_beads`)."""
        beads = self.max_beads()
        return MEMORY_BASE_BYTES + MEMORY_PER_BEAD_BYTES * beads + MEMORY_PER_OWN_BEAD_BYTES * beads / self.processes

    def _check_size(self) -> None:
        """Refuse a packing that this machine's memory cannot hold, counted without building it
        (:meth:`max_beads`); the builders word any error in the sizes themselves."""
        if not self.diameter_m > 0 or any(
            getattr(self, key) < 1
            for key in ("edge_beads", "long_edge", "short_edge", "radius_beads", "rows", "columns", "beads")
        ):
            return
        needed = self.memory_estimate_bytes() * self.processes
        available = available_memory_bytes()
        if needed > available:
            raise HexdemError(
                f"{self.shape} of up to {self.max_beads():,} beads needs about {needed / 1e9:.3g} GB of "
                f"memory ({self.processes} process(es)); this machine has {available / 1e9:.3g} GB "
                "available"
            )

    @classmethod
    def from_toml(cls, path) -> RunConfig:
        """Read a TOML file whose keys are :class:`RunConfig` field names (:func:`read_config_table`)."""
        return cls.from_dict(read_config_table(path), source=str(path))

    @classmethod
    def from_dict(cls, data: dict, source: str = "config", given: bool = True) -> RunConfig:
        """The configuration of the table ``data`` of keys, each key in it set whatever its value
        (:meth:`set_keys`); ``given=False`` for a table hexdem wrote with every key (a deck's
        ``hexdem.json``), whose keys are set where they differ from their defaults. An unknown
        key is refused in one line that names the nearest known one."""
        known = [f.name for f in dataclasses.fields(cls)]
        for key in data:
            if key not in known:
                nearest = difflib.get_close_matches(key, known, n=3)
                hint = (
                    f"did you mean {' or '.join(nearest)}?" if nearest else f"the keys are {', '.join(sorted(known))}"
                )
                raise HexdemError(f"{source}: unknown parameter {key}; {hint}")
        return cls(**data, given=frozenset(data) if given else frozenset())

    def replace(self, **changes) -> RunConfig:
        """This configuration with ``changes`` that hexdem makes (a derived run's): a key changed
        is no longer the user's, and is set only where it differs from its default."""
        return dataclasses.replace(self, given=self.given - changes.keys(), **changes)

    def override(self, **changes) -> RunConfig:
        """This configuration with ``changes`` that the user makes (a command line's options, the
        Python API's keywords): each key set whatever its value, as if written in the file."""
        return dataclasses.replace(self, given=self.given | changes.keys(), **changes)

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)

    def set_keys(self) -> list[str]:
        """The keys this configuration sets, in the fields' order: those the user wrote
        (``given``), whatever their value, and those whose value differs from their default. These
        are the keys that may be refused for describing another shape
        (:func:`~hexdem.model.packing_builders.check_shape_keys`) or for doing nothing
        (:mod:`~hexdem.model.unused_keys`)."""
        return [
            field.name
            for field in dataclasses.fields(self)
            if field.name in self.given
            or getattr(self, field.name)
            != (field.default_factory() if field.default is dataclasses.MISSING else field.default)
        ]

    def shape_dict(self) -> dict:
        """:meth:`as_dict` less the keys that describe other shapes (:data:`SHAPE_KEYS`): the keys
        that apply to this run, which ``summary.json`` records."""
        return {key: value for key, value in self.as_dict().items() if self.shape in SHAPE_KEYS.get(key, (self.shape,))}

    def material(self, name: str) -> Material:
        """The material called ``name``: a preset or one of this configuration's ``materials``."""
        return material(name, custom_materials(self.materials))

    @property
    def effective_wall_restitution(self) -> float:
        """The bead–wall restitution: ``wall_restitution``, or the beads' ``restitution`` if None."""
        return self.restitution if self.wall_restitution is None else self.wall_restitution

    @property
    def unit_system(self) -> UnitSystem:
        """The units of ``v0``, ``dt``, ``duration`` and of every result of this run."""
        return SI if self.units == "si" else nondimensional(self.diameter_m, self.material(self.bead_material))

    @property
    def inward_deg(self) -> float:
        """The direction from the struck bead into the packing [deg from +x]: a chain's ``angle_deg``;
        0 for every other shape, struck through the wall whose inward normal is +x."""
        return self.angle_deg if self.shape == "chain" else 0.0

    @property
    def strike_direction_deg(self) -> float:
        """The strike's direction [deg from +x]: ``strike_angle_deg``, or if None :attr:`inward_deg`."""
        return self.inward_deg if self.strike_angle_deg is None else self.strike_angle_deg

    def impact_specs(self) -> list[ImpactSpec]:
        """The configured impacts, the run's values filled in (:func:`~hexdem.model.impacts.impact_specs`)."""
        return impact_specs(
            self.impacts,
            self.v0,
            self.strike_direction_deg,
            self.impact,
            self.striker_material,
            self.striker_diameter_m,
        )
