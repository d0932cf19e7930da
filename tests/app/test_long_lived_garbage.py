"""A catalog built as long-lived (:func:`building_long_lived`) freezes no garbage (#44 item 1): every element
refresh froze the cyclic garbage alive at that moment into the collector's permanent generation, where it is
never collected; a station re-reading its elements every 3 minutes kept all of it."""

from __future__ import annotations

import gc
import weakref

from nfwserver.app.long_lived import building_long_lived


class _Node:
    def __init__(self) -> None:
        self.me = self  # a reference cycle: only the cyclic collector frees it


def test_cyclic_garbage_alive_at_a_refresh_is_still_collected() -> None:
    gc.collect()
    try:
        rings = []
        for _ in range(20):  # twenty refreshes, each with some cyclic garbage lying about
            node = _Node()
            rings.append(weakref.ref(node))
            del node
            with building_long_lived():
                kept = [object() for _ in range(10)]  # the "catalog"
            del kept
        gc.collect()
        assert [r for r in rings if r() is not None] == []  # before: all 20 frozen, never to be freed
    finally:
        gc.unfreeze()
