"""The one error type hexdem raises for problems a user can fix.

Following ASE's ``CLIError``: every expected failure (bad input, missing LAMMPS, a
LAMMPS error, a corrupt dump) becomes a :class:`HexdemError` whose message is a single
line naming the problem; the CLI prints it without a traceback.
"""


class HexdemError(Exception):
    """A problem with hexdem's input or environment, explained in one line."""


def one_line(exc: BaseException) -> str:
    """What a failure says to the user in one line: a HexdemError's own message, anything else
    prefixed with its type (an unexpected error, reported rather than hidden)."""
    message = str(exc) if isinstance(exc, HexdemError) else f"{type(exc).__name__}: {exc}"
    return message.replace("\n", " ")
