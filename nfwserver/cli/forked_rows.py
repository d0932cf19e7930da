"""A large output's rows made by several processes and written in order by this one.

The text of a whole catalog's week (650,000 passes, 90 MB of CSV) takes a process 1.5 s to make, a fifth of
the command.  Each slab's text depends on that slab's rows alone (and, for a table, on the widths found first),
so forked processes can make some while this one makes others and writes them all in their order: the bytes are
those of one process.  Only the text comes
back (pickled through a pipe); the rows reach the forked processes with the fork.  POSIX only (fork); one
process elsewhere, or for one slab.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # multiprocessing is imported only when processes are forked
    from multiprocessing.connection import Connection

#: Slab ``k``'s text and how many rows it holds.
MakeText = Callable[[int], tuple[str, int]]


def write_in_order(count: int, make: MakeText, put: Callable[[str, int], object], processes: int) -> None:
    """``put`` the texts ``make`` makes of slabs ``0 .. count - 1``, in that order.  With ``processes`` > 1
    (POSIX), process ``p`` of them makes slabs ``p, p + processes, ...``: this one is process 0 and writes each
    slab as its turn comes, waiting for the forked one that makes it (which makes its next meanwhile).  A
    failure in any of them reaches the caller, and the forked ones are ended."""
    processes = min(processes, count)
    if processes <= 1 or sys.platform == "win32":
        for k in range(count):
            put(*make(k))
        return
    import multiprocessing

    context = multiprocessing.get_context("fork")  # which flushes the standard streams before each fork
    receivers: list[Connection] = []
    forked = []
    try:
        for p in range(1, processes):
            receiver, sender = context.Pipe(duplex=False)
            process = context.Process(target=_make_texts, args=(make, range(p, count, processes), sender),
                                      daemon=True)
            process.start()
            sender.close()  # the child holds its own end: EOF here if it dies without its texts
            receivers.append(receiver)
            forked.append(process)
        for k in range(count):
            p = k % processes
            if not p:
                put(*make(k))
                continue
            try:
                made = receivers[p - 1].recv()
            except EOFError:  # killed (out of memory, a signal) before it sent this slab
                forked[p - 1].join(5.0)
                raise OSError(f"a process making rows ended before it made them all (exit status "
                              f"{forked[p - 1].exitcode})") from None
            if isinstance(made, BaseException):
                raise made
            put(*made)
        for process in forked:
            process.join()
    finally:
        for receiver in receivers:
            receiver.close()
        for process in forked:
            if process.is_alive():
                process.terminate()
                process.join()


def _make_texts(make: MakeText, slabs: Iterable[int], results: Connection) -> None:
    """A forked process's whole life: the texts of ``slabs``, sent one by one in order (or the exception that
    stopped it).  Each send waits until the parent reads it, so at most one text waits in this process."""
    try:
        try:
            for k in slabs:
                results.send(make(k))
        except BaseException as exc:  # handed to the parent, which raises it
            results.send(exc)
    except OSError:  # the parent has gone (it failed itself, and ends this process)
        pass
    finally:
        results.close()
