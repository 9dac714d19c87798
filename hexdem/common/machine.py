"""What this machine can hold and what this job may use: available memory and free disk, for
refusing jobs that cannot fit, and the CPUs the job may run on."""

from __future__ import annotations

import os
import shutil
from pathlib import Path


def available_memory_bytes() -> int:
    """Memory the kernel can give without swapping (``MemAvailable``), or the physical total."""
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")


def free_disk_bytes(path) -> int:
    """Free space on the file system that holds ``path`` (or its nearest existing parent)."""
    path = Path(path).absolute()
    while not path.exists():
        path = path.parent
    return shutil.disk_usage(path).free


def usable_cpus() -> int:
    """The CPUs this process may run on: its CPU affinity, which Slurm, taskset and container
    limits set (``os.sched_getaffinity``), or where that is unknown every core (``os.cpu_count``)."""
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1
