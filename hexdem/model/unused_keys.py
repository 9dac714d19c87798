"""Keys that another key's value leaves without effect, refused so that no key is silently ignored.

:func:`~hexdem.model.packing_builders.check_shape_keys` refuses a key that describes another
shape. These keys describe the shape, but what another key says makes them do nothing: a
striker's material when no impact is a striker, a sampling rate without sensors, a wall's
material or restitution where the packing has no walls, MPI ranks or a dump on the reference
engine. A configuration a user gives (``hexdem run``, ``hexdem compare``) is refused when it sets
one (:func:`check_unused_keys`), and a sweep when every one of its runs does
(:func:`check_unused_in_every`), in one line that names the key, the key that leaves it idle, and
both ways out. The configurations hexdem derives from a user's (a random disc's packing run, a
deck read back, the reference side of a comparison, :func:`on_engine`) are not checked.
"""

from __future__ import annotations

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
        how = (
            'no [[impacts]] table is a striker; set kind = "striker" on one'
            if config.impacts
            else f'no impact is a striker (impact = "{config.impact}"); set impact = "striker"'
        )
        idle.update(dict.fromkeys(STRIKER_KEYS, f"{how} or remove it"))
    if config.engine == "reference":
        idle.update(
            dict.fromkeys(
                LAMMPS_KEYS,
                "the reference engine runs in one process and writes no dump "
                '(engine = "reference"); use engine = "lammps" or remove it',
            )
        )
    if not config.sensors:
        idle.update(dict.fromkeys(SENSOR_KEYS, "there are no sensors; add sensors or remove it"))
    if config.shape in ("packing", "random") and config.walls == "none":
        idle.update(
            dict.fromkeys(WALL_KEYS, 'the packing has no walls (walls = "none"); set walls = "hull" or remove it')
        )
    elif config.wall_material == "none":
        idle.update(
            dict.fromkeys(
                WALL_KEYS[1:], 'the packing has no walls (wall_material = "none"); name a wall material or remove it'
            )
        )
    return idle


def set_idle_keys(config) -> dict[str, str]:
    """:func:`idle_keys` less those the configuration does not set
    (:meth:`~hexdem.model.config.RunConfig.set_keys`: a key the user wrote is set whatever its
    value) and a wall material of ``"none"``, which says the same as no walls; in the order of the
    configuration's fields."""
    idle = idle_keys(config)
    return {
        key: idle[key]
        for key in config.set_keys()
        if key in idle and not (key == "wall_material" and config.wall_material == "none")
    }


def check_unused_keys(config) -> None:
    """Refuse, in one line, the first key that ``config`` sets and its other keys leave without
    effect (:func:`set_idle_keys`): the check of a configuration a user gives (``hexdem run``,
    ``hexdem compare``). Configurations that hexdem derives from one (a random disc's packing run,
    a deck read back) are not checked: they may leave a key idle that the user's configuration uses."""
    for key, why in set_idle_keys(config).items():
        raise HexdemError(f"{key} does nothing: {why}")


def check_unused_in_every(configs) -> None:
    """Refuse, in one line, the first key that every one of ``configs`` (a sweep's runs) sets and
    leaves without effect: a key idle in some runs only acts in the others (a sweep that varies
    ``impact`` over velocity and striker keeps its ``striker_material``)."""
    idle = [set_idle_keys(config) for config in configs]
    for key, why in (idle[0] if idle else {}).items():
        if all(key in found for found in idle[1:]):
            raise HexdemError(f"{key} does nothing in any run of the sweep: {why}")


def on_engine(config, engine: str):
    """``config`` run by ``engine``: on the reference engine, the keys that LAMMPS alone acts on
    (:data:`LAMMPS_KEYS`) at the values it takes them at, for the studies that hand one
    configuration to both engines (``hexdem compare``, a sweep that varies ``engine``)."""
    return config.replace(engine=engine, **(LAMMPS_KEYS if engine == "reference" else {}))
