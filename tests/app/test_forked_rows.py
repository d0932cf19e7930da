"""A large output's slabs made by forked processes and written in order (:mod:`nfwserver.cli.forked_rows`):
each slab by its process, every slab once and in order; a failure anywhere reaches the caller and leaves no
process behind; nothing the parent had not yet flushed is written twice."""

from __future__ import annotations

import multiprocessing
import os
import signal
import subprocess
import sys

import pytest

from nfwserver.cli.forked_rows import write_in_order
from nfwserver.forked_children import can_fork
from tests.conftest import ROOT

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="fork")
PYTEST = os.getpid()  #: the process running the tests, which a slab must never kill


@pytest.fixture
def forking() -> None:
    """For the tests of the forked path: with another thread running (pytest-timeout's thread method, a test's
    leftover) this process would make every slab itself, and the killing slab would end pytest."""
    if not can_fork():
        pytest.skip("another thread is running, so write_in_order does not fork")


def _made_by(k: int) -> tuple[str, int]:
    return f"{k} {os.getpid()}\n", 1


def _written(count: int, make, processes: int) -> list[tuple[str, int]]:
    out: list[tuple[str, int]] = []
    write_in_order(count, make, lambda text, rows: out.append((text, rows)), processes)
    return out


@pytest.mark.usefixtures("forking")
@pytest.mark.parametrize("processes", [1, 2, 3, 9])
def test_every_slab_once_in_order_each_made_by_its_process(processes: int) -> None:
    out = _written(7, _made_by, processes)
    slabs = [int(text.split()[0]) for text, _ in out]
    makers = [int(text.split()[1]) for text, _ in out]
    assert slabs == list(range(7)) and all(rows == 1 for _, rows in out)
    used = min(processes, 7)
    assert makers[0] == os.getpid()  # this process makes slab 0, 0 + n, ...
    assert len(set(makers)) == used  # one process per share, no more
    for p in range(used):
        assert len({makers[k] for k in range(p, 7, used)}) == 1
    assert multiprocessing.active_children() == []


def test_no_slab_writes_nothing() -> None:
    assert _written(0, _made_by, 2) == []


def _fails_in_a_forked_process(k: int) -> tuple[str, int]:
    if k == 3:
        raise ValueError("slab 3 cannot be made")
    return _made_by(k)


def test_a_failure_in_a_forked_process_reaches_the_caller() -> None:
    out: list[str] = []
    with pytest.raises(ValueError, match="slab 3"):
        write_in_order(6, _fails_in_a_forked_process, lambda text, rows: out.append(text), 2)
    assert [int(text.split()[0]) for text in out] == [0, 1, 2]  # in order up to the failure
    assert multiprocessing.active_children() == []


def _killed_in_a_forked_process(k: int) -> tuple[str, int]:
    if k == 1 and os.getpid() != PYTEST:
        os.kill(os.getpid(), signal.SIGKILL)
    return _made_by(k)


@pytest.mark.usefixtures("forking")
def test_a_killed_forked_process_is_an_error_not_missing_rows() -> None:
    with pytest.raises(OSError, match="a row-making process ended without its answer"):
        _written(4, _killed_in_a_forked_process, 2)
    assert multiprocessing.active_children() == []


def test_a_failure_to_write_ends_the_forked_processes() -> None:
    def put(text: str, rows: int) -> None:
        raise BrokenPipeError("the reader has gone")

    with pytest.raises(BrokenPipeError):
        write_in_order(40, _made_by, put, 3)
    assert multiprocessing.active_children() == []


_PENDING = """
import sys
from nfwserver.cli.forked_rows import write_in_order
sys.stdout.write("header\\n")  # still in the buffer when the processes are forked
write_in_order(4, lambda k: (f"slab {k}\\n", 1), lambda text, rows: sys.stdout.write(text), 2)
"""


def test_what_the_parent_had_not_flushed_is_written_once() -> None:
    """A forked process flushes the standard streams it inherited when it ends (multiprocessing flushes them
    before it forks; a bare ``os.fork`` would not)."""
    done = subprocess.run([sys.executable, "-c", _PENDING], cwd=ROOT, capture_output=True, text=True, timeout=60,
                          check=True)
    assert done.stdout == "header\nslab 0\nslab 1\nslab 2\nslab 3\n"
