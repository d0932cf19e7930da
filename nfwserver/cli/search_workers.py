"""How many worker processes ``passes --workers auto`` forks for a search: one per core not busy now.

Kept out of the tracking engine, which does no I/O of its own: this reads ``/proc/loadavg``.  Any number of
workers gives the same passes, bit for bit (:mod:`nfwserver.tracking.pass_workers`).
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Sequence

#: Fewest satellites for which :func:`auto_workers` forks (below, forking and gathering cost about what they save).
AUTO_WORKERS_FROM = 1000
#: Most worker processes :func:`auto_workers` chooses.
AUTO_WORKERS_MAX = 8
#: Readings of the running processes :func:`busy_cores` takes, and the pause between them (s).
_BUSY_READINGS, _BUSY_GAP_S = 3, 0.003


def auto_workers(satellites: int) -> int:
    """Worker processes that pay for a search of ``satellites`` here and now: one per core not already busy
    (the cores this process may use less :func:`busy_cores`), from :data:`AUTO_WORKERS_FROM` satellites; 1 on
    Windows (no fork).  Any number gives the same passes, bit for bit."""
    if satellites < AUTO_WORKERS_FROM or sys.platform == "win32":
        return 1
    cores = os.cpu_count() or 1
    if sys.platform == "linux":
        cores = len(os.sched_getaffinity(0))  # the cores this process may run on
    return max(1, min(cores - busy_cores(), AUTO_WORKERS_MAX))


def busy_cores(readings: Sequence[str] | None = None) -> int:
    """Cores other processes keep busy now.  On Linux, the most processes found running besides this one in three
    readings of ``/proc/loadavg``'s fourth field a few milliseconds apart (``readings``: those texts); elsewhere,
    or when it cannot be read, the 1-minute load average.  The average lags by a minute: a command run right
    after another heavy one (a script running several searches in a row) would see its predecessor's load and
    give up cores that are idle now, and one run just after a heavy job started would take cores that are not;
    three readings keep a process that is runnable most of the time from being missed."""
    if sys.platform == "win32":  # no load average (and no fork: auto_workers chooses 1 there)
        return 0
    if readings is None:
        readings = []
        for k in range(_BUSY_READINGS):
            try:
                with open("/proc/loadavg", encoding="ascii") as f:
                    readings.append(f.read())
            except OSError:
                break
            if k + 1 < _BUSY_READINGS:
                time.sleep(_BUSY_GAP_S)
    running = []
    for text in readings:
        try:
            running.append(int(text.split()[3].split("/")[0]) - 1)
        except (IndexError, ValueError):
            break
    else:
        if running:
            return max(0, max(running))
    return int(os.getloadavg()[0])
