"""How a failing rank of an MPI job tells the process that launched it why, in one line.

Every rank that fails may report, and ``MPI_Abort`` from the first one kills the others
wherever they are, mid-write included: so the report is written atomically (a reader sees a
whole message or none), and the job is aborted only after it is in place.
"""

from __future__ import annotations

import os
import sys

from hexdem.common.io import write_text
from hexdem.errors import one_line

#: Environment variable naming the file where a failing rank leaves its one-line error
#: before it aborts the MPI job (each rank of a job sets it from the job's path).
ERROR_FILE_VARIABLE = "HEXDEM_JOB_ERROR"


def abort_job(comm, exc: BaseException) -> None:
    """Leave ``exc``'s one-line message where ``$HEXDEM_JOB_ERROR`` says, then end the whole
    MPI job (the other ranks would wait for this one in a collective call). ``MPI_Abort``
    need not stop its caller at once: a caller must return, not go on with its work."""
    path = os.environ.get(ERROR_FILE_VARIABLE)
    if path:
        write_text(path, one_line(exc) + "\n")
    sys.stderr.flush()
    comm.Abort(1)
