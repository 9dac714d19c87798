"""Values checked against their declared types, before anything uses them.

A parameter object declares each key's type in its annotations: ``int``, ``float``, ``str``,
``bool``, unions such as ``float | None`` or ``str | int``, ``tuple[X, ...]`` (a list of X, as
TOML writes it), ``tuple[X, Y]`` (a list of exactly those), ``dict[str, X]`` (a table of X) and
``TypedDict`` tables (each known key of its type; unknown keys are left to the code that reads
the table, which words them), and any other class (an instance of it). :func:`check_type` refuses a value of another
type in one line
naming the key, the type and the value; :func:`type_at` finds the declared type of a dotted
path into the tables and lists, so that a value can be checked before it is put there.

``int`` is an integer, not a bool; ``float`` is a finite number (an integer too); ``None`` is
allowed only where the type says ``| None``.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import numbers
import types
import typing

from hexdem.errors import HexdemError


@functools.cache
def declared_types(cls) -> dict:
    """{key: type} of the annotations of ``cls`` (a dataclass or a TypedDict), resolved; a
    dataclass's init-only arguments (``InitVar``) are not keys."""
    return {key: kind for key, kind in typing.get_type_hints(cls).items() if not isinstance(kind, dataclasses.InitVar)}


def _is_list(args) -> bool:
    """Whether a tuple type's ``args`` are ``(X, ...)``: a list of any length."""
    return len(args) == 2 and args[1] is Ellipsis


#: Scalar types in words: (one, several).
NOUNS = {
    bool: ("true or false", "trues or falses"),
    int: ("an integer", "integers"),
    float: ("a number", "numbers"),
    str: ("a string", "strings"),
}


def describe(kind, plural: bool = False) -> str:
    """The type ``kind`` in words, as a message says it (``plural``: several of them)."""
    if kind in NOUNS:
        return NOUNS[kind][plural]
    origin, args = typing.get_origin(kind), typing.get_args(kind)
    if origin in (typing.Union, types.UnionType):
        return " or ".join(describe(arg, plural) for arg in args if arg is not type(None))
    if typing.is_typeddict(kind):
        words = f"table{'s' if plural else ''} of {', '.join(declared_types(kind))}"
    elif origin is tuple and _is_list(args):
        words = f"list{'s' if plural else ''} of {describe(args[0], True)}"
    elif origin is tuple:
        parts = (
            f"{len(args)} {describe(args[0], True)}"
            if len(set(args)) == 1
            else ", ".join(describe(arg) for arg in args)
        )
        words = f"list{'s' if plural else ''} of {parts}"
    elif origin is dict:
        words = f"table{'s' if plural else ''} of {describe(args[1], True)}"
    else:
        words = f"{kind.__name__}{'s' if plural else ''}"
    return words if plural else f"a {words}"


def _matches(value, kind, name: str) -> bool:
    """Whether ``value`` is of type ``kind``; a part of a table or list of the wrong type raises,
    naming its own path under ``name``."""
    if kind is bool:
        return isinstance(value, bool)
    if kind is int:
        return isinstance(value, numbers.Integral) and not isinstance(value, bool)
    if kind is float:
        return isinstance(value, numbers.Real) and not isinstance(value, bool) and math.isfinite(value)
    if kind is str:
        return isinstance(value, str)
    if kind is type(None):
        return value is None
    origin, args = typing.get_origin(kind), typing.get_args(kind)
    if origin in (typing.Union, types.UnionType):
        return any(_matches(value, arg, name) for arg in args)
    if typing.is_typeddict(kind):
        if isinstance(value, dict):
            for key, part in declared_types(kind).items():
                if key in value:
                    check_type(f"{name}.{key}", value[key], part)
        return isinstance(value, dict)
    if origin is tuple and _is_list(args):
        if isinstance(value, (list, tuple)):
            for k, item in enumerate(value):
                check_type(f"{name}.{k}", item, args[0])
        return isinstance(value, (list, tuple))
    if origin is tuple:
        return (
            isinstance(value, (list, tuple))
            and len(value) == len(args)
            and all(_matches(item, arg, f"{name}.{k}") for k, (item, arg) in enumerate(zip(value, args)))
        )
    if origin is dict:
        if isinstance(value, dict):
            for key, item in value.items():
                check_type(f"{name}.{key}", item, args[1])
        return isinstance(value, dict)
    return isinstance(value, kind)


def check_type(name: str, value, kind) -> None:
    """Refuse ``value`` unless it is of the declared type ``kind``, in one line naming ``name``."""
    if not _matches(value, kind, name):
        raise HexdemError(f"{name} must be {describe(kind)}, got {value!r}")


def check_fields(obj) -> None:
    """Check every annotated field of the dataclass instance ``obj`` against its declared type."""
    for name, kind in declared_types(type(obj)).items():
        check_type(name, getattr(obj, name), kind)


def _arm_for(kind, step: str):
    """The part of the union ``kind`` that a path can step into with ``step``: a list for an
    index, a table for a key (``materials``: a table of materials or a list of names)."""
    if typing.get_origin(kind) not in (typing.Union, types.UnionType):
        return kind
    for arm in typing.get_args(kind):
        if (typing.get_origin(arm) is tuple) == step.isdigit() and arm is not type(None):
            return arm
    return None


def type_at(cls, path: str):
    """The declared type of the dotted ``path`` into ``cls``'s keys, tables and lists
    (``regions.0.material``: ``str``), or None where the path leaves what is declared."""
    steps = path.split(".")
    kind = declared_types(cls).get(steps[0])
    for step in steps[1:]:
        kind = _arm_for(kind, step)
        args = typing.get_args(kind)
        if typing.is_typeddict(kind):
            kind = declared_types(kind).get(step)
        elif typing.get_origin(kind) is dict:
            kind = args[1]
        elif typing.get_origin(kind) is tuple and step.isdigit():
            index = int(step)
            kind = args[0] if _is_list(args) else (args[index] if index < len(args) else None)
        else:
            return None
    return kind
