"""An element download's deadline is the operator's ``--timeout`` for the whole transfer, connect included
(#45 item 7: ``elements update`` of an address that never answered took 26.6 s under Wine to say "no answer
within 20 s").  Real loopback sockets: a listener that never accepts (its backlog full, so a connect is never
answered) and one that accepts and never sends a byte; the deadline runs on a virtual clock, so the test
proves it is measured on the clock it is given and that a connect in progress is cut at it."""

from __future__ import annotations

import socket
import threading
from collections.abc import Iterator
from datetime import datetime, timezone

import pytest

from nfwserver.app.element_sources import SourceError, fetch_url
from nfwserver.clock import VirtualClock
from tests.conftest import advance_until


def _listener(backlog: int) -> socket.socket:
    server = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    server.bind(("127.0.0.1", 0))
    server.listen(backlog)
    return server


@pytest.fixture
def never_accepts() -> Iterator[str]:
    """A loopback port whose listen queue is full: a new connect gets no answer at all (its SYN is dropped)."""
    server = _listener(0)
    port = server.getsockname()[1]
    queued: list[socket.socket] = []
    try:
        while True:  # fill the queue: the first connect that does not complete at once is the blackhole's proof
            client = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
            client.settimeout(0.3)
            queued.append(client)
            try:
                client.connect(("127.0.0.1", port))
            except TimeoutError:
                break
            assert len(queued) < 16, "the listen queue never filled"
        yield f"http://127.0.0.1:{port}/elements.txt"
    finally:
        for client in queued:
            client.close()
        server.close()


@pytest.fixture
def never_answers() -> Iterator[str]:
    """A loopback server that accepts every connection and never sends a byte."""
    server = _listener(8)
    accepted: list[socket.socket] = []
    stop = threading.Event()

    def accept() -> None:
        server.settimeout(0.05)
        while not stop.is_set():
            try:
                accepted.append(server.accept()[0])
            except (TimeoutError, OSError):
                continue

    thread = threading.Thread(target=accept, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.getsockname()[1]}/elements.txt"
    finally:
        stop.set()
        thread.join(5.0)
        for sock in accepted:
            sock.close()
        server.close()


def _fetch_on(clock: VirtualClock, url: str, timeout_s: float) -> tuple[float, str]:
    """Fetch ``url`` in a thread while stepping ``clock``; (virtual seconds it took, the one-line error)."""
    errors: list[str] = []
    done = threading.Event()

    def fetch() -> None:
        try:
            fetch_url(url, timeout_s, clock=clock)
        except SourceError as exc:
            errors.append(str(exc))
        finally:
            done.set()

    thread = threading.Thread(target=fetch, daemon=True)
    thread.start()
    assert advance_until(clock, done.is_set, step_s=0.5, limit_s=3 * timeout_s, real_timeout_s=15.0), \
        "the fetch outlived three times its deadline"
    thread.join(5.0)
    assert len(errors) == 1
    return clock.monotonic(), errors[0]


@pytest.mark.parametrize("server", ["never_accepts", "never_answers"])
def test_the_whole_transfer_connect_included_ends_at_the_operators_timeout(server: str,
                                                                          request: pytest.FixtureRequest) -> None:
    url = request.getfixturevalue(server)
    clock = VirtualClock(datetime(2026, 11, 28, tzinfo=timezone.utc))
    took_s, error = _fetch_on(clock, url, 20.0)
    assert error == f"cannot fetch {url}: the whole transfer did not end within 20 s"
    assert 20.0 <= took_s <= 20.5  # the deadline, on the clock it was given (one step of the test's stepping)
