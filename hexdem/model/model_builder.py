"""The model a configuration describes: its packing, materials, walls, impacts and sensors.

:class:`~hexdem.model.config.RunConfig` is the schema: it holds the keys and checks each of
them. This module builds from it, as ASE's builders make an ``Atoms`` apart from what is done
with it: the shape's packing (:func:`~hexdem.model.packing_builders.shape_packing`), less the
``vacancies`` and with the extra observation ``lines``; the materials of its regions; the
precompressed geometry (:mod:`hexdem.model.precompression`); the impacts and the holes they
cut in the walls; the initial state; and the sensors. The time step and the run's length
follow from the built model (:mod:`hexdem.model.run_settings`).
"""

from __future__ import annotations

from hexdem.errors import HexdemError
from hexdem.model.contact_law import Friction
from hexdem.model.granular import GranularModel, Impact
from hexdem.model.impacts import resolve_impacts, struck_site
from hexdem.model.initial_state import read_initial_state
from hexdem.model.lines import with_lines
from hexdem.model.materials import hertz_coefficient, hertz_stiffness
from hexdem.model.packing import Packing
from hexdem.model.packing_builders import PLACED_SHAPES, BuiltPacking, shape_packing
from hexdem.model.precompression import hole_force, precompressed_packing
from hexdem.model.regions import assign_materials
from hexdem.model.sensors import sensor_beads
from hexdem.model.triangular import without_sites
from hexdem.model.walls import cut_holes, without_hole


def configured_packing(config) -> BuiltPacking:
    """The packing of ``config`` (a :class:`~hexdem.model.config.RunConfig`): its ``shape``'s,
    less the ``vacancies``, struck at the first impact's site, with the extra observation
    ``lines``, and the material regions of its builder."""
    built = shape_packing(config, struck_site(config.impact_specs()))
    packing = without_hole(built.packing) if config.impacts else built.packing  # each impact cuts its own
    packing = without_sites(packing, config.vacancies) if config.vacancies else packing
    return BuiltPacking(with_lines(packing, config.lines) if config.lines else packing, built.regions)


def build_packing(config) -> Packing:
    """The packing of :func:`configured_packing`, without its material regions."""
    return configured_packing(config).packing


def _precompressed(config, packing: Packing, extra, bead, wall) -> tuple[Packing, tuple[float, float]]:
    """The packing squeezed by ``precompression_n`` and the force that holds the struck bead in
    its hole (:mod:`hexdem.model.precompression`), after checking that the packing allows it."""
    if extra:
        raise HexdemError("precompression is built for a packing of one material; drop the regions")
    if wall is None:
        raise HexdemError('a precompressed packing needs walls to hold it (wall_material = "none")')
    if config.shape == "half-disc":
        raise HexdemError("a precompressed packing needs walls all round; the half-disc's arc is free")
    if config.shape in ("disc", "sites") + PLACED_SHAPES:
        raise HexdemError(
            f"precompression is built for flat-walled basins (hexagon, half-hexagon, triangle, "
            f"parallelogram), not shape = {config.shape!r}"
        )
    coefficient = float(hertz_coefficient(config.diameter_m, bead))
    packing = precompressed_packing(packing, config.precompression_n, coefficient, hertz_stiffness(bead, wall))
    return packing, tuple(float(f) for f in hole_force(packing, config.precompression_n))


def build_model(config) -> GranularModel:
    """The SI :class:`~hexdem.model.granular.GranularModel` that ``config`` describes."""
    wall = None if config.wall_material == "none" else config.material(config.wall_material)
    bead, held = config.material(config.bead_material), (0.0, 0.0)
    built = configured_packing(config)
    if len(built.packing) < 2 and not built.packing.walls:
        raise HexdemError(
            f"{built.packing.shape}: a packing needs at least 2 beads, or 1 bead and a wall to rebound "
            "from; a lone free bead carries no wave"
        )
    packing, extra = assign_materials(built.packing, built.regions + config.regions, bead, config.material)
    if config.precompression_n > 0:
        packing, held = _precompressed(config, packing, extra, bead, wall)
    impacts = model_impacts(config, packing)
    if config.impacts:
        holed, opened = cut_holes(packing, impacts)
        if config.precompression_n > 0:
            if opened - {packing.struck}:
                raise HexdemError(
                    "a precompressed packing holds only the first impact's bead in a hole of its "
                    "wall; strike the other beads inside the packing"
                )
            held = held if packing.struck in opened else (0.0, 0.0)
        packing = holed
    state = None if config.initial_state_file is None else read_initial_state(config.initial_state_file, packing)
    return GranularModel(
        packing,
        impacts[0],
        bead,
        wall,
        config.restitution,
        config.effective_wall_restitution,
        held,
        tuple(sensor_beads(config.sensors, packing).values()),
        config.sensor_mass_factor,
        extra,
        tuple(impacts[1:]),
        Friction.of(config.friction, config.wall_friction, config.rolling_friction),
        state,
    )


def model_impacts(config, packing: Packing) -> list[Impact]:
    """The model's impacts: the paper's single one on the struck bead, or those of ``impacts``."""
    if not config.impacts:
        striker = None if config.striker_material is None else config.material(config.striker_material)
        bead = packing.struck if config.shape == "chain" else None  # a chain's way in is along it, at any angle
        return [
            Impact(
                config.v0 * config.unit_system.velocity_m_s,
                config.strike_direction_deg,
                config.impact == "striker",
                bead,
                striker,
                config.striker_diameter_m,
            )
        ]
    return resolve_impacts(config.impact_specs(), packing, config.unit_system.velocity_m_s, config.material)
