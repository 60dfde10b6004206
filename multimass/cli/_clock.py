"""When a command started: the start of its process, so its reported wall time is what the
user waited for (interpreter start-up, imports and loading the compiled kernels included).
"""

from __future__ import annotations

import os
import sys
import time

__all__ = ["command_start", "process_start"]

#: A process-start reading further back than this is not trusted (a long-lived process).
_MAX_AGE_S = 120.0


def process_start() -> float | None:
    """The `time.perf_counter` reading at which this process started, or None.

    Linux only: the start time in ``/proc/self/stat`` (clock ticks since boot, 10 ms
    resolution) against ``CLOCK_BOOTTIME``. None elsewhere, or when the reading is
    implausible (negative, or more than two minutes back).
    """
    if not sys.platform.startswith("linux"):
        return None
    try:
        with open("/proc/self/stat", "rb") as f:  # fields after "(name)": state is field 3
            ticks = int(f.read().rsplit(b")", 1)[1].split()[19])  # field 22, starttime
        age = time.clock_gettime(time.CLOCK_BOOTTIME) - ticks / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError, AttributeError):
        return None
    if not 0.0 <= age <= _MAX_AGE_S:
        return None
    return time.perf_counter() - age


def command_start(console: bool) -> float:
    """The `time.perf_counter` reading a command's wall time counts from.

    The start of the process when the command runs as the ``multimass`` console script
    (`console`), else now (a command run from Python, e.g. ``main([...])`` in a session).
    """
    start = process_start() if console else None
    return time.perf_counter() if start is None else start
