"""Processes forked to work beside this one, each answering through a pipe of its own (POSIX).

The pass search's workers (:mod:`nfwserver.tracking.pass_workers`) and the makers of a large output's text
(:mod:`nfwserver.cli.forked_rows`) share this life cycle:

- a child is forked with what it needs (no pickling on the way in) and sends its answers back pickled; an
  exception that ends it is its last answer, raised in the parent when read;
- each child closes, first thing, the ends of the pipes it inherited that are not its to write: had it kept
  the parent's reading ends, a parent killed (a signal, the out-of-memory killer) would leave it blocked
  forever in a send to a pipe nobody reads, holding its memory and the command's standard output;
- a child that dies without an answer is an :class:`OSError` in the parent, with its exit status;
- whatever way the parent leaves (done, failed, interrupted), every child is ended and reaped.

:func:`can_fork` says when forking is safe: not on Windows (no fork), and only while this process runs a
single thread (a lock another thread holds at the fork stays held, forever, in the child).
"""

from __future__ import annotations

import sys
import threading
from collections.abc import Callable
from types import TracebackType
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # multiprocessing is imported only when processes are forked (1.3 MiB, 5 ms)
    from multiprocessing.connection import Connection
    from multiprocessing.process import BaseProcess


def can_fork() -> bool:
    """True when this process may fork helpers: a POSIX system with ``fork``, and no other thread running."""
    if sys.platform == "win32" or threading.active_count() != 1:
        return False
    import multiprocessing

    return "fork" in multiprocessing.get_all_start_methods()


class ForkedChildren:
    """Children forked by :meth:`start`, read by :meth:`recv`; a context manager that ends them all at its end.
    ``what`` names a child in the error raised when one dies without answering (e.g. "a pass-search worker")."""

    def __init__(self, what: str) -> None:
        self.what = what
        self._receivers: list[Connection] = []
        self._processes: list[BaseProcess] = []

    def start(self, target: Callable[..., None], args: tuple[Any, ...]) -> None:
        """Fork a child running ``target(*args, sender)``, ``sender`` the writing end of its pipe; answers are
        read with :meth:`recv` by the child's number (from 0)."""
        import multiprocessing

        if sys.platform == "win32":  # never true here (callers check can_fork); it tells the type checker so
            raise OSError("fork is POSIX only")
        context = multiprocessing.get_context("fork")  # which flushes the standard streams before forking
        receiver, sender = context.Pipe(duplex=False)
        inherited = [*self._receivers, receiver]
        process = context.Process(target=_child, args=(target, args, sender, inherited), daemon=True)
        try:
            process.start()
        except BaseException:  # not forked (no memory, too many processes): the pipe is nobody's
            receiver.close()
            sender.close()
            raise
        sender.close()  # the child holds its own: EOF here if it dies without an answer
        self._receivers.append(receiver)
        self._processes.append(process)

    def recv(self, k: int) -> object:
        """Child ``k``'s next answer (blocks until it comes); the exception that ended the child is raised."""
        try:
            answer: object = self._receivers[k].recv()
        except EOFError:  # killed (out of memory, a signal) before it answered
            process = self._processes[k]
            process.join(5.0)
            raise OSError(f"{self.what} process ended without its answer (exit status {process.exitcode})"
                          ) from None
        if isinstance(answer, BaseException):
            raise answer
        return answer

    def join(self) -> None:
        """Wait for every child to end (after their last answers)."""
        for process in self._processes:
            process.join()

    def __enter__(self) -> ForkedChildren:
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        for receiver in self._receivers:  # a child still sending gets a broken pipe and ends
            receiver.close()
        for process in self._processes:
            if process.is_alive():
                process.terminate()
                process.join()


def _child(target: Callable[..., None], args: tuple[Any, ...], sender: Connection, inherited: list[Connection]
           ) -> None:
    """A child's whole life: the parent's reading ends it inherited closed, then ``target``, whose exception,
    if it raises one, is the child's last answer (:meth:`ForkedChildren.recv` raises it in the parent)."""
    for receiver in inherited:
        receiver.close()
    try:
        try:
            target(*args, sender)
        except BaseException as exc:
            sender.send(exc)
    except OSError:  # the parent has gone (killed, or ending the children after a failure of its own)
        pass
    finally:
        sender.close()
