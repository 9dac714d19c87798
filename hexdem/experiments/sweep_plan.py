"""The plan of ``hexdem sweep``: which runs a study of any run-config keys makes, checked whole
before any of them runs.

The runs are the product of the varied values, in the order given (the last ``--vary`` changes
fastest). A varied KEY is a :class:`~hexdem.model.config.RunConfig` key, or a path into one
through its tables and lists: ``regions.0.material`` (the first region's material),
``impacts.1.v0`` (the second impact's speed). The path's last step may add a key the base
configuration leaves at its default; the steps before it must exist there. Values are read as
TOML values (``0.4``, ``1e-3``, ``true``, ``"brass"``); a bare word is a string
(``brass``). Each value is checked against its key's declared type as it is read
(:func:`~hexdem.common.typecheck.type_at`), and every run's configuration is built and
validated (its keys by :class:`RunConfig`, its model and time step by
:func:`~hexdem.model.run_settings.run_settings`, a random disc's on its loose start by
:func:`~hexdem.experiments.random_packing.check_random_run`) before anything runs, so a bad key
or value is one line naming the key or the run.

A run's name, its directory under ``DIR/runs/``, is its ``key=value`` pairs joined by commas,
as given on the command line (characters a file name cannot hold become ``_``).
"""

from __future__ import annotations

import copy
import itertools
import re
import tomllib
from dataclasses import dataclass, fields

from hexdem.common.typecheck import check_type, type_at
from hexdem.errors import HexdemError
from hexdem.experiments.random_packing import check_random_run
from hexdem.model.config import RunConfig, read_config_table
from hexdem.model.model_builder import build_model
from hexdem.model.packing_builders import PREPARED_SHAPES
from hexdem.model.run_settings import run_settings
from hexdem.model.unused_keys import check_unused_in_every

#: Characters kept as they are in a run's directory name.
NAME_CHARACTERS = re.compile(r"[^A-Za-z0-9._=,+-]")


@dataclass(frozen=True)
class Variation:
    """One ``--vary KEY=V1,V2,...``: the ``key`` (a dotted path), its ``values`` as read from
    TOML and their ``texts`` as given (they name the runs)."""

    key: str
    values: tuple
    texts: tuple[str, ...]

    @classmethod
    def parse(cls, option: str) -> Variation:
        """``KEY=V1,V2,...`` → a variation; a malformed option is one clear line."""
        key, sign, listed = option.partition("=")
        key, texts = key.strip(), tuple(text.strip() for text in listed.split(","))
        if not sign or not key or not all(texts):
            raise HexdemError(f"--vary {option!r}: expected KEY=V1,V2,... with no empty value")
        if len(set(texts)) != len(texts):
            raise HexdemError(f"--vary {key}: a value is listed twice ({listed})")
        top = key.split(".")[0]
        known = {f.name for f in fields(RunConfig)}
        if top not in known:
            raise HexdemError(f"--vary {key}: {top!r} is not a run-config key; known: {', '.join(sorted(known))}")
        values = tuple(toml_value(text) for text in texts)
        if (kind := type_at(RunConfig, key)) is not None:
            for value in values:
                check_type(f"--vary {key}", value, kind)
        if any(a == b and type(a) is type(b) for i, a in enumerate(values) for b in values[i + 1 :]):
            raise HexdemError(f"--vary {key}: two values are the same once read ({listed})")
        return cls(key, values, texts)


def toml_value(text: str):
    """``text`` read as a TOML value, or as a string if it is not one (a bare word)."""
    try:
        return tomllib.loads(f"value = {text}")["value"]
    except tomllib.TOMLDecodeError:
        return text


def _step(container, step: str, path: str, option: str):
    if isinstance(container, list):
        if not re.fullmatch(r"[0-9]+", step) or int(step) >= len(container):
            raise HexdemError(f"{option} {path}: the base configuration has no item {step} (it has {len(container)})")
        return int(step)
    if isinstance(container, dict):
        return step
    raise HexdemError(f"{option} {path}: {step!r} is inside a value that is neither a table nor a list")


def with_value(data: dict, path: str, value, option: str = "--vary") -> dict:
    """A copy of the configuration ``data`` with the dotted ``path`` set to ``value``; errors name
    the path as the command-line ``option`` that gave it."""
    changed = copy.deepcopy(data)
    steps = path.split(".")
    container = changed
    for step in steps[:-1]:
        index = _step(container, step, path, option)
        if isinstance(container, dict) and index not in container:
            raise HexdemError(f"{option} {path}: the base configuration has no {step!r} to change a part of")
        container = container[index]
    container[_step(container, steps[-1], path, option)] = value
    return changed


@dataclass(frozen=True)
class SweepRun:
    """One run of a sweep: its ``name`` (directory under ``runs/``), the varied ``values``
    {key: value} and its validated ``config``."""

    name: str
    values: dict
    config: RunConfig


def run_name(pairs) -> str:
    """The directory name of the run with (key, text) ``pairs``."""
    return NAME_CHARACTERS.sub("_", ",".join(f"{key}={text}" for key, text in pairs))


def plan_sweep(base: dict, variations: list[Variation], source: str = "the base configuration") -> list[SweepRun]:
    """Every run of the sweep of ``variations`` on the configuration ``base`` (a TOML table of
    run-config keys), each validated; bad input is one line naming the run."""
    if not variations:
        raise HexdemError("a sweep needs at least one --vary KEY=V1,V2,...")
    keys = [v.key for v in variations]
    if len(set(keys)) != len(keys):
        raise HexdemError(f"--vary: a key is varied twice ({', '.join(keys)})")
    RunConfig.from_dict(base, source=source)
    runs = []
    for chosen in itertools.product(*(range(len(v.values)) for v in variations)):
        data, pairs = base, []
        for variation, i in zip(variations, chosen):
            data = with_value(data, variation.key, variation.values[i])
            pairs.append((variation.key, variation.texts[i]))
        name = run_name(pairs)
        try:
            config = RunConfig.from_dict(data, source=f"run {name}")
            if config.shape in PREPARED_SHAPES:  # packed by LAMMPS when it runs: checked on its loose start
                check_random_run(config)
            else:
                run_settings(config, build_model(config))
        except HexdemError as exc:
            message = str(exc)
            raise HexdemError(message if message.startswith(f"run {name}") else f"run {name}: {message}") from None
        if config.ranks != 1:
            raise HexdemError(
                f"run {name}: a sweep runs each run on one rank of its own (--workers runs at "
                f"once); leave ranks at 1, got {config.ranks}"
            )
        runs.append(
            SweepRun(name, {variation.key: variation.values[i] for variation, i in zip(variations, chosen)}, config)
        )
    check_unused_in_every([run.config for run in runs])
    names = [run.name for run in runs]
    if len(set(names)) != len(names):
        raise HexdemError(
            "--vary: two runs would share a directory name; use values that differ in letters, digits or . _ = , + -"
        )
    return runs


def read_base(path) -> dict:
    """The base configuration file's table (empty: the built-in default experiment), a relative
    ``packing_file`` read from its folder as ``hexdem run`` reads it."""
    return {} if path is None else read_config_table(path)
