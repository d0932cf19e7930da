"""Worker processes for large pass searches: how the search's chunks are shared among them, and the forked
processes themselves (how many pay is the command's choice: :mod:`nfwserver.cli.search_workers`).

Each worker searches whole chunks of the one-process search's plan (:mod:`~nfwserver.tracking.passes`) exactly as
one process would, so any number of workers finds the same passes, bit for bit.  Workers are forked (POSIX): the
satellites' SGP4 models reach them with the fork (they cannot be pickled) and only the passes come back.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator, Sequence, Sized
from typing import IO, TYPE_CHECKING, Any, Protocol

from nfwserver.forked_children import ForkedChildren
from nfwserver.tracking.pass_spill import SpilledPasses

if TYPE_CHECKING:  # multiprocessing is imported only when workers are forked (1.3 MiB, 5 ms)
    from multiprocessing.connection import Connection
    from multiprocessing.sharedctypes import Synchronized

    from nfwserver.tracking.pass_records import PassList

#: The one-process search (``passes._search``): satellites, then its other arguments.
Search = Callable[..., "PassList | SpilledPasses"]
#: Work of one possible pass in coarse samples, for sharing chunks among workers (refining a pass costs ~15
#: times a coarse sample; ``room`` counts every pass an orbit could give, of which about half are seen).
_PASS_WORK = 8.0


class ChunkWork(Protocol):
    """What :func:`pull_order` reads of a chunk of the search's plan (``passes._Chunk``)."""

    @property
    def members(self) -> Sized: ...  # the satellites searched together
    @property
    def step_s(self) -> float: ...  # coarse step (s)
    @property
    def extension_s(self) -> float: ...  # look-back and -ahead (s)
    @property
    def room(self) -> int: ...  # passes there can be


def pull_order(plan: Sequence[ChunkWork], window_s: float) -> list[int]:
    """The order in which workers take the chunks of ``plan`` (indices): the most work first, so that the last
    chunks taken are small and the workers end together.  A chunk's work is counted as its coarse samples
    (satellites times the searched span, ``window_s`` plus the look-back and -ahead, over the step) plus
    :data:`_PASS_WORK` per pass there can be (``room``)."""
    work = [len(c.members) * (window_s + 2.0 * c.extension_s) / c.step_s + _PASS_WORK * c.room for c in plan]
    return sorted(range(len(plan)), key=lambda i: -work[i])


class _Pulled:
    """The chunks one worker searches: each taken, when the worker is ready for it, as the next of ``order``
    that no worker has taken yet (``taken``: a counter the forked workers share).  A forked worker whose parent
    (the process that made this) has gone takes none: nobody would read its passes."""

    def __init__(self, plan: Sequence[ChunkWork], order: list[int], taken: Synchronized[int]) -> None:
        self.plan, self.order, self.taken = plan, order, taken
        self.parent = os.getpid()

    def __iter__(self) -> Iterator[ChunkWork]:
        while True:
            if os.getpid() != self.parent and os.getppid() != self.parent:  # orphaned (the command was killed)
                return
            with self.taken.get_lock():
                k = self.taken.value
                self.taken.value = k + 1
            if k >= len(self.order):
                return
            yield self.plan[self.order[k]]

    def stop(self) -> None:
        """Leave no chunk to take: every worker stops after the chunk it is searching (one has failed)."""
        with self.taken.get_lock():
            self.taken.value = len(self.order)


def fork_worker(search: Search, satellites: list[Any], args: tuple[Any, ...], results: Connection) -> None:
    """A forked worker's whole life: the passes of the chunks it takes (``search(satellites, *args)``, the
    one-process search of :mod:`~nfwserver.tracking.passes`; ``args[0]`` the :class:`_Pulled` chunks), sent back
    through ``results``; a failure first tells the other workers to stop, then reaches the parent
    (:class:`~nfwserver.forked_children.ForkedChildren`).  Runs in the child only; the satellites reached it by
    the fork (Satrec objects cannot be pickled), only the result is pickled.  A search that spills (``args``'
    last, a SpilledPasses on a file the parent made) writes its rows to that file and sends back only what
    orders them (:meth:`SpilledPasses.keys`) and the satellites it left out."""
    try:
        found = search(satellites, *args)
    except BaseException:
        args[0].stop()
        raise
    results.send(_answer(found))


def _answer(found: PassList | SpilledPasses) -> object:
    """What a worker hands back of its passes ``found``: the passes, or the keys and skipped satellites of its
    spilled rows."""
    return (found.keys(), found.skipped) if isinstance(found, SpilledPasses) else found


def in_forked_workers(search: Search, satellites: list[Any], plan: Sequence[ChunkWork], args: tuple[Any, ...],
                      workers: int, spills: Sequence[IO[bytes]] = ()) -> list[Any]:
    """The passes of the chunks of ``plan`` found by ``workers`` processes running ``search`` (``search(satellites,
    chunks, room, *args)``): this one and ``workers - 1`` forked ones, in that order (the caller checked
    :func:`~nfwserver.forked_children.can_fork`).  Each worker takes the next chunk (in :func:`pull_order`) when
    it is ready for one, and searches it whole as one process would, so the passes are those of one process bit
    for bit whichever worker found them; dealing the chunks out beforehand left one of two workers idle for up
    to a third of the search (the chunks' work is known only roughly).  With ``spills`` (one temporary file per
    worker), each worker writes its rows to its file and hands back their keys (:func:`fork_worker`)."""
    import multiprocessing

    context = multiprocessing.get_context("fork")
    window_s = (args[2] - args[1]).total_seconds()
    order = pull_order(plan, window_s)
    taken = context.Value("q", 0)  # the next place in ``order``, shared by the workers
    room = -(-sum(c.room for c in plan) // workers)  # a worker's room for passes to start with (grown if need be)

    def share(k: int) -> tuple[Any, ...]:  # worker k's arguments to ``search`` after the satellites
        spill = (SpilledPasses(args[1], window_s, spills[k]),) if spills else ()
        return (_Pulled(plan, order, taken), room, *args, *spill)

    with ForkedChildren("a pass-search worker") as children:
        for k in range(1, workers):  # this process is worker 0: one fork and one answer fewer to pass back
            children.start(fork_worker, (search, satellites, share(k)))
        mine = share(0)
        try:
            outcomes = [_answer(search(satellites, *mine))]
        except BaseException:
            mine[0].stop()  # the children stop after their chunk on their own, besides being ended below
            raise
        outcomes += [children.recv(k) for k in range(workers - 1)]  # before joining: a large answer fills the pipe
        children.join()
    return outcomes


