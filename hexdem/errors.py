"""The one error type hexdem raises for problems a user can fix.

Following ASE's ``CLIError``: every expected failure (bad input, missing LAMMPS, a
LAMMPS error, a corrupt dump) becomes a :class:`HexdemError` whose message is a single
line naming the problem; the CLI prints it without a traceback. A simulation that started
and failed raises the subclass :class:`RunFailed`, so that the CLI's exit status tells it from
input that was refused before anything ran.
"""


class HexdemError(Exception):
    """A problem with hexdem's input or environment, explained in one line."""


class RunFailed(HexdemError):
    """A simulation that started and failed: LAMMPS stopped with an error, the integration went
    wrong (its energy drifted), or a settling deck did not settle."""


def one_line(exc: BaseException) -> str:
    """What a failure says to the user in one line: a HexdemError's own message, anything else
    prefixed with its type (an unexpected error, reported rather than hidden); each run of
    whitespace (line breaks included) one space."""
    message = str(exc) if isinstance(exc, HexdemError) else f"{type(exc).__name__}: {exc}"
    return " ".join(message.split())
