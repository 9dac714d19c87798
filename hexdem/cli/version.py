"""``hexdem --version``: hexdem's version (and commit, from a checkout), LAMMPS's and the MPI library's.

Computed only when asked for: it loads the LAMMPS and MPI libraries but starts no simulation.
"""

from __future__ import annotations

import argparse

from hexdem.experiments.provenance import versions


def version_text() -> str:
    """The lines ``hexdem --version`` prints (:func:`~hexdem.experiments.provenance.versions`)."""
    v = versions()
    commit = f" (git {v['git_commit']})" if v["git_commit"] else ""
    return (
        f"hexdem {v['hexdem_version']}{commit}\n{v['lammps_version']}\n{v['mpi_version']}\nPython {v['python_version']}"
    )


class VersionAction(argparse.Action):
    """Like argparse's ``version`` action, with the text computed when the option is given."""

    def __init__(self, option_strings, dest, **kwargs):
        super().__init__(
            option_strings,
            dest,
            nargs=0,
            default=argparse.SUPPRESS,
            help="print hexdem's, LAMMPS's and the MPI library's versions and exit",
        )

    def __call__(self, parser, namespace, values, option_string=None):
        print(version_text())
        parser.exit()
