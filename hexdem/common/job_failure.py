"""How a failing rank of an MPI job tells the process that launched it why, in one line.

Every rank that fails may report, and ``MPI_Abort`` from the first one kills the others
wherever they are, mid-write included: so the report is written atomically (a reader sees a
whole message or none), and the job is aborted only after it is in place. A second line says
whether the rank refused its input (a :class:`~hexdem.errors.HexdemError`) or the run failed
(a :class:`~hexdem.errors.RunFailed`, or an unexpected error), so that the launching process
raises the same kind of error (:func:`reported_error`) and the command ends with its status.
"""

from __future__ import annotations

import os
import sys

from hexdem.common.io import write_text
from hexdem.errors import HexdemError, RunFailed, one_line

#: Environment variable naming the file where a failing rank leaves its one-line error
#: before it aborts the MPI job (each rank of a job sets it from the job's path).
ERROR_FILE_VARIABLE = "HEXDEM_JOB_ERROR"
#: The report's second line: the rank refused its input, or its run failed.
REFUSED, FAILED = "refused", "failed"


def abort_job(comm, exc: BaseException) -> None:
    """Leave ``exc``'s one-line message where ``$HEXDEM_JOB_ERROR`` says, then end the whole
    MPI job (the other ranks would wait for this one in a collective call). ``MPI_Abort``
    need not stop its caller at once: a caller must return, not go on with its work."""
    path = os.environ.get(ERROR_FILE_VARIABLE)
    if path:
        refused = isinstance(exc, HexdemError) and not isinstance(exc, RunFailed)
        write_text(path, f"{one_line(exc)}\n{REFUSED if refused else FAILED}\n")
    sys.stderr.flush()
    comm.Abort(1)


def reported_error(report: str) -> HexdemError:
    """The error a rank's report (:func:`abort_job`) stands for: its one-line message, as a
    :class:`~hexdem.errors.HexdemError` if the rank refused its input, else as a
    :class:`~hexdem.errors.RunFailed`."""
    message, _, kind = report.strip().partition("\n")
    return (HexdemError if kind.strip() == REFUSED else RunFailed)(message)
