"""Keep freed memory in the process, for the next sample's arrays of the same size.

A run hands its analysis a few fresh (n, 2) arrays per sample and frees them after. glibc's
``malloc`` serves blocks of 128 kB and more (n ≳ 8,000 beads) by ``mmap`` and unmaps them when
freed, or trims them off its heap, so the next sample's arrays are faulted in again page by page,
which costs a large sample more than its arithmetic (docs/validation/benchmarks.md, *Figures
behind choices in the code*). With both thresholds raised (``mmap`` only above
:data:`MMAP_THRESHOLD_BYTES`, trimming only above :data:`TRIM_THRESHOLD_BYTES` free at the heap's
top) the freed blocks are reused as they are. The process's peak memory is what it was: the kept
blocks are those the next sample takes again.
"""

from __future__ import annotations

import ctypes

#: ``mallopt``'s parameter numbers (glibc's malloc.h).
M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3
#: Blocks up to this size come from the heap (glibc's upper limit for this threshold).
MMAP_THRESHOLD_BYTES = 32 << 20
#: The heap keeps up to this much free memory at its top.
TRIM_THRESHOLD_BYTES = 256 << 20


def keep_freed_memory() -> bool:
    """Raise this process's ``malloc`` thresholds (see the module docstring). Returns whether it
    could: False where the C library has no ``mallopt`` (not glibc), which changes nothing else."""
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    mapped = bool(mallopt(M_MMAP_THRESHOLD, MMAP_THRESHOLD_BYTES))
    return mapped and bool(mallopt(M_TRIM_THRESHOLD, TRIM_THRESHOLD_BYTES))
