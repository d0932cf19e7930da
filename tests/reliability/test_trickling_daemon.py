"""A Hamlib peer that trickles its replies one byte at a time must not hold the worker: each reply has a
whole-reply deadline (real seconds), the link shows the fault, and a daemon answering normally again clears it.

The peer is a real loopback socket speaking rotctld's protocol; real time is used because the per-read
and whole-reply timeouts are real socket timeouts.
"""

from __future__ import annotations

import socket
import threading
import time
from datetime import datetime, timezone

import pytest

from nfwserver.clock import VirtualClock
from nfwserver.hamlib.commands import GET_POSITION
from nfwserver.hamlib.connection import HamlibConnection, HamlibUnavailable


class TricklingPeer:
    """Answers ``p`` with two position lines, sent one byte every ``delay_s`` while ``trickle`` is set."""

    def __init__(self, delay_s: float) -> None:
        self.delay_s = delay_s
        self.trickle = threading.Event()
        self.trickle.set()
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.port = self.listener.getsockname()[1]
        self.closed = False
        threading.Thread(target=self._serve, daemon=True).start()

    def _serve(self) -> None:
        while not self.closed:
            try:
                conn, _ = self.listener.accept()
            except OSError:
                return
            threading.Thread(target=self._talk, args=(conn,), daemon=True).start()

    def _talk(self, conn: socket.socket) -> None:
        with conn:
            try:
                while conn.recv(4096):
                    reply = b"180.000000\n45.000000\n"
                    if not self.trickle.is_set():
                        conn.sendall(reply)
                        continue
                    for i in range(len(reply)):
                        conn.sendall(reply[i:i + 1])
                        time.sleep(self.delay_s)
            except OSError:
                return

    def close(self) -> None:
        self.closed = True
        self.listener.close()


@pytest.fixture
def peer():
    p = TricklingPeer(delay_s=0.1)  # 22 bytes: 2.2 s a reply, each byte well within the 1 s read timeout
    yield p
    p.close()


def test_a_trickled_reply_is_cut_at_the_deadline_and_the_link_heals(peer: TricklingPeer) -> None:
    clock = VirtualClock(datetime(2026, 5, 8, tzinfo=timezone.utc))
    conn = HamlibConnection("127.0.0.1", peer.port, clock, name="rotctld", timeout_s=1.0, reply_deadline_s=0.5)
    started = time.monotonic()
    with pytest.raises(HamlibUnavailable, match="no whole reply within 0.5 s"):
        conn.call(GET_POSITION)
    assert time.monotonic() - started < 1.2  # not the 2.2 s the peer takes, nor hours for a slower one
    assert not conn.health.ok and "no whole reply" in conn.health.describe()
    peer.trickle.clear()  # the daemon answers normally again
    clock.advance(2.0)  # past the back-off
    assert conn.call(GET_POSITION) == ["180.000000", "45.000000"]
    assert conn.health.ok


def test_a_reply_that_arrives_slowly_keeps_the_link_failing_until_a_prompt_one(monkeypatch) -> None:
    """A daemon whose replies make the deadline but only just (the campaign's trickling rigctld: a set's
    ``RPRT 0`` in 1.8 s of a 2 s deadline) looked healthy between the replies that missed it, while the
    radio lagged: STATUS did not explain those ticks.  A reply slower than SLOW_REPLY_S is now a symptom."""
    import nfwserver.hamlib.connection as connection

    monkeypatch.setattr(connection, "SLOW_REPLY_S", 0.3)  # the peer takes 0.1 s a byte: 2.2 s a reply
    slow = TricklingPeer(delay_s=0.02)  # 22 bytes: 0.44 s, within the deadline, over SLOW_REPLY_S
    try:
        clock = VirtualClock(datetime(2026, 5, 8, tzinfo=timezone.utc))
        conn = HamlibConnection("127.0.0.1", slow.port, clock, name="rigctld", timeout_s=1.0, reply_deadline_s=2.0)
        assert conn.call(GET_POSITION) == ["180.000000", "45.000000"]  # answered, so the value is used
        assert not conn.health.ok and "answers slowly" in conn.health.describe()
        slow.trickle.clear()
        assert conn.call(GET_POSITION) == ["180.000000", "45.000000"]
        assert conn.health.ok
    finally:
        slow.close()


def test_a_rotor_behind_a_slow_daemon_is_failing_in_status_not_ok(monkeypatch) -> None:
    """STATUS said ``rotor=ok`` beside ``faults=rotctld`` while the daemon answered slowly: the rotor's one
    word (STATUS, console, web page) now comes from its daemon link too, and is ``ok`` again after a prompt
    reply."""
    import nfwserver.hamlib.connection as connection
    from nfwserver.rotor.geometry import RotorGeometry
    from nfwserver.rotor.kct_driver import KctDriver
    from nfwserver.rotor.rotctld_backend import RotctldBackend

    monkeypatch.setattr(connection, "SLOW_REPLY_S", 0.3)
    slow = TricklingPeer(delay_s=0.02)  # 0.44 s a reply: within the deadline, over SLOW_REPLY_S
    try:
        clock = VirtualClock(datetime(2026, 5, 8, tzinfo=timezone.utc))
        driver = KctDriver(clock, RotctldBackend(clock, RotorGeometry(), port=slow.port))
        assert driver.read_position() == (180.0, 45.0)  # answered: the position is used
        assert driver.link_state() == "failing"
        slow.trickle.clear()
        assert driver.read_position() == (180.0, 45.0)
        assert driver.link_state() == "ok"
    finally:
        slow.close()
