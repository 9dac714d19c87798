"""The one error type hexdem raises for problems a user can fix.

Following ASE's ``CLIError``: every expected failure (bad input, missing LAMMPS, a
LAMMPS error, a corrupt dump) becomes a :class:`HexdemError` whose message is a single
line naming the problem; the CLI prints it without a traceback.
"""


class HexdemError(Exception):
    """A problem with hexdem's input or environment, explained in one line."""
