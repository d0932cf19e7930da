"""A large output's rows made by several processes and written in order by this one.

The text of a whole catalog's week (650,000 passes, 90 MB of CSV) takes a process 1.5 s to make, a fifth of
the command.  Each slab's text depends on that slab's rows alone (and, for a table, on the widths found first),
so forked processes can make some while this one makes others and writes them all in their order: the bytes
are those of one process.  Only the text comes back (pickled through a pipe); the rows reach the forked
processes with the fork.  A slab is one block of rows (:data:`nfwserver.cli.bulk_output.BLOCK_ROWS`), so the
text waiting in either process is one block's.  Where forking is not safe (Windows, or other threads running:
:func:`~nfwserver.forked_children.can_fork`), or for one slab, this process makes every slab.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, cast

from nfwserver.forked_children import ForkedChildren, can_fork

if TYPE_CHECKING:
    from multiprocessing.connection import Connection

#: Slab ``k``'s text and how many rows it holds.
MakeText = Callable[[int], tuple[str, int]]


def write_in_order(count: int, make: MakeText, put: Callable[[str, int], object], processes: int) -> None:
    """``put`` the texts ``make`` makes of slabs ``0 .. count - 1``, in that order.  With ``processes`` > 1
    (where :func:`~nfwserver.forked_children.can_fork`), process ``p`` of them makes slabs ``p, p + processes,
    ...``: this one is process 0 and writes each slab as its turn comes, waiting for the forked one that makes
    it (which makes its next meanwhile).  A failure in any of them reaches the caller, and the forked ones are
    ended."""
    processes = min(processes, count)
    if processes <= 1 or not can_fork():
        for k in range(count):
            put(*make(k))
        return
    with ForkedChildren("a row-making") as children:
        for p in range(1, processes):
            children.start(_make_texts, (make, range(p, count, processes)))
        for k in range(count):
            p = k % processes
            made = make(k) if not p else children.recv(p - 1)
            text, rows = cast("tuple[str, int]", made)  # what _make_texts sends
            put(text, rows)
        children.join()


def _make_texts(make: MakeText, slabs: Iterable[int], results: Connection) -> None:
    """A forked process's whole life: the texts of ``slabs``, sent one by one in order.  Each send waits until
    the parent reads it, so at most one text waits in this process."""
    for k in slabs:
        results.send(make(k))
