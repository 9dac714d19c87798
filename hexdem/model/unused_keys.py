"""Keys that another key's value leaves without effect, refused so that no key is silently ignored.

:func:`~hexdem.model.packing_builders.check_shape_keys` refuses a key that describes another
shape. These keys describe the shape, but what another key says makes them do nothing: a
striker's material when no impact is a striker, a sampling rate without sensors, a wall's
material or restitution where the packing has no walls, MPI ranks or a dump on the reference
engine. Each is refused when it is set (differs
from its default), in one line that names the key, the key that leaves it idle, and both ways out.
"""

from __future__ import annotations

import dataclasses

from hexdem.errors import HexdemError

#: The striker's keys: they act only where an impact is a striker.
STRIKER_KEYS = ("striker_material", "striker_diameter_m")
#: The sensors' keys: they act only on sensors.
SENSOR_KEYS = ("sensor_rate_hz", "sensor_mass_factor")
#: The walls' keys: they act only on walls.
WALL_KEYS = ("wall_material", "wall_restitution", "wall_friction")
#: The keys that LAMMPS alone acts on, with the values that the reference engine (one process, no
#: dump) takes them at: :func:`on_engine` sets them so.
LAMMPS_KEYS = {"ranks": 1, "dump": False}


def idle_keys(config) -> dict[str, str]:
    """{key: why it does nothing, and the ways out} for the keys of ``config`` (a
    :class:`~hexdem.model.config.RunConfig`) that its other keys leave without effect, set or not."""
    idle = {}
    if not any(spec.striker for spec in config.impact_specs()):
        idle.update(dict.fromkeys(STRIKER_KEYS, f'no impact is a striker (impact = "{config.impact}"); set '
                                                'impact = "striker" or remove it'))
    if config.engine == "reference":
        idle.update(dict.fromkeys(LAMMPS_KEYS, 'the reference engine runs in one process and writes no dump '
                                               '(engine = "reference"); use engine = "lammps" or remove it'))
    if not config.sensors:
        idle.update(dict.fromkeys(SENSOR_KEYS, "there are no sensors; add sensors or remove it"))
    if config.shape in ("packing", "random") and config.walls == "none":
        idle.update(dict.fromkeys(WALL_KEYS, 'the packing has no walls (walls = "none"); set walls = "hull" or '
                                             "remove it"))
    elif config.wall_material == "none":
        idle.update(dict.fromkeys(WALL_KEYS[1:], 'the packing has no walls (wall_material = "none"); name a wall '
                                                 "material or remove it"))
    return idle


def check_unused_keys(config) -> None:
    """Refuse, in one line, the first key of ``config`` that is set (not its default, nor
    ``"none"`` for a wall material where there are no walls) and that its other keys leave without
    effect (:func:`idle_keys`)."""
    idle = idle_keys(config)
    for field in dataclasses.fields(config):
        if field.name not in idle:
            continue
        default = field.default_factory() if field.default is dataclasses.MISSING else field.default
        value = getattr(config, field.name)
        if value != default and not (field.name == "wall_material" and value == "none"):
            raise HexdemError(f"{field.name} does nothing: {idle[field.name]}")


def on_engine(config, engine: str):
    """``config`` run by ``engine``: on the reference engine, the keys that LAMMPS alone acts on
    (:data:`LAMMPS_KEYS`) at the values it takes them at, for the studies that hand one
    configuration to both engines (``hexdem compare``, a sweep that varies ``engine``)."""
    return config.replace(engine=engine, **(LAMMPS_KEYS if engine == "reference" else {}))
