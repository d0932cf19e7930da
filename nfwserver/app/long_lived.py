"""Building large, long-lived object graphs (an element catalog) without pausing other threads.

CPython's cyclic garbage collector holds the interpreter lock for a whole collection, and a full
collection walks every tracked object: with a 100,000-set catalog in memory, one takes about 150 ms,
on whichever thread happened to allocate -- the publish thread included.  Building a catalog
allocates hundreds of thousands of objects and so triggers several such collections (measured: 0.2 s
gaps in a 10 Hz feed during a refresh; docs/RELIABILITY.md).

:func:`building_long_lived` pauses collection while the block runs (the objects it makes have no
cycles: they are freed by reference counting), then moves every object alive at that moment into the
collector's permanent generation (``gc.freeze``), so later collections, on any thread, do not walk the
catalog again.  Frozen objects are still freed by reference counting when released; cyclic garbage
alive at a freeze would never be collected, so the first block to start collects first (cheap: what
an earlier freeze moved out is not walked again).  Without that, every element refresh froze whatever
cyclic garbage the station had made since the last one, for good (#44: a station re-reading its elements
every 3 minutes grew by megabytes an hour).  Only the garbage made by other threads during the build
itself can still be frozen.  The collector is process-wide: nested and concurrent uses count, and the last one to leave
re-enables it (if it was enabled before the first).

Freeing is the other pause: the last reference to a list of 100,000 sets, dropped at once, frees them all
in one call (about 45 ms).  :func:`release` drops them one at a time instead.
"""

from __future__ import annotations

import gc
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

_lock = threading.Lock()
_depth = [0]  # how many blocks are running, in every thread
_was_enabled = [True]


@contextmanager
def building_long_lived() -> Iterator[None]:
    """Run the block with cyclic collection paused, then freeze what is alive (see the module docstring)."""
    with _lock:
        if _depth[0] == 0:
            _was_enabled[0] = gc.isenabled()
            gc.collect()  # no cyclic garbage into the permanent generation (see the module docstring)
            gc.disable()
        _depth[0] += 1
    try:
        yield
    finally:
        with _lock:
            _depth[0] -= 1
            if _depth[0] == 0:
                gc.freeze()
                if _was_enabled[0]:
                    gc.enable()


def release(items: list[Any]) -> None:
    """Empty ``items`` one element at a time, so that freeing what only it held never holds the lock long."""
    while items:
        items.pop()
