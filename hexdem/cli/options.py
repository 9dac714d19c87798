"""Command-line options that several subcommands share."""

from __future__ import annotations


def add_launcher(parser, appended: str = "-n N python -P -m hexdem.experiments.parallel JOB") -> None:
    """``--launcher CMD``: the MPI launcher that starts hexdem's ranks, on this machine or across
    as many as it reaches; ``appended`` is what hexdem adds to it (for the help text)."""
    parser.add_argument(
        "--launcher",
        metavar="CMD",
        help=f'MPI launcher to which "{appended}" is appended (default: this environment\'s '
        'mpiexec), e.g. "mpiexec -f hosts" or "srun"; given, the job goes through it even '
        "on one rank",
    )


def add_parsl(parser) -> None:
    """``--parsl CONFIG.py``: hand the study's runs to Parsl (:mod:`hexdem.experiments.executors`)."""
    parser.add_argument(
        "--parsl",
        metavar="CONFIG.py",
        help="hand the runs to Parsl: a Parsl configuration file that defines config = "
        "parsl.config.Config(...) (default: --workers local processes)",
    )


def add_workers_or_parsl(parser, default: int, help_text: str) -> None:
    """``--workers N`` (local processes, ``default``) or ``--parsl CONFIG.py``, not both: Parsl
    places the runs itself, so the pair is a usage error rather than a ``--workers`` ignored."""
    where = parser.add_mutually_exclusive_group()
    # a string default, which argparse converts only when --workers is absent: a --workers N that
    # equals the default is then seen as given (argparse compares the value with the default by identity)
    where.add_argument("--workers", type=int, default=str(default), metavar="N", help=help_text)
    add_parsl(where)
