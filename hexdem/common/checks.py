"""Checks of user-supplied numbers shared by hexdem's parameter objects.

Each parameter object words its own one-line :class:`~hexdem.errors.HexdemError`; these
helpers only decide what counts as a usable number, the same way everywhere.
"""

from __future__ import annotations

import math
import numbers

from hexdem.errors import HexdemError


def is_number(value) -> bool:
    """True for a finite real number; False for bools, NaN, ±inf, strings and None."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool) and math.isfinite(value)


def positive_number(name: str, value) -> float:
    """``value`` as a float if it is a finite number > 0, else a HexdemError naming ``name``."""
    if not (is_number(value) and value > 0):
        raise HexdemError(f"{name} must be a number > 0, got {value!r}")
    return float(value)


def positive_int(name: str, value) -> int:
    """``value`` as an int if it is an integer ≥ 1, else a HexdemError naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < 1:
        raise HexdemError(f"{name} must be a positive integer, got {value!r}")
    return int(value)
