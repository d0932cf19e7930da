"""The soak's STATUS poller reports a failed sample and carries on sampling.

In the recorded 47-minute soak the STATUS samples ended at about minute 36 with nothing said: the poller
swallowed every failure and retried silently.  Here a station on a real loopback socket answers two STATUS
requests, then stops answering (the poller's read times out), then refuses the next connection with an
``ERROR`` line (as ``nfwserver.tcp.admission`` does) and closes it, then answers again: each failure must be
counted and said, and the samples must go on after them.
"""

from __future__ import annotations

import socket
import threading
import time

import pytest

from bench.soak.load import Load
from nfwserver.tcp.greeting import GREETING
from tests.waiting import wait_for

STATUS = b"satellite=25544 tune=on faults=none rotor=ok radio=ok\r\n"


def _station(listener: socket.socket, done: threading.Event, refused: list[float]) -> None:
    """Connection 1: greeting, two answers, then silence; 2: a refusal line and a close (when: ``refused``);
    3: answers."""
    for n in range(1, 4):
        conn, _ = listener.accept()
        with conn:
            if n == 2:
                conn.sendall(b"ERROR the station serves 1 connections at most; try again later\r\n")
                refused.append(time.monotonic())
                continue
            conn.sendall(GREETING.encode() + b"\r\n")
            answered = 0
            while not done.is_set():
                data = conn.recv(1024)
                if not data:
                    break
                if n == 1 and answered == 2:
                    done.wait(3.0)  # hold the connection open, say nothing: the poller's read times out
                    break
                conn.sendall(STATUS * data.count(b"STATUS"))
                answered += data.count(b"STATUS")


def test_failed_status_samples_are_counted_said_and_sampling_goes_on(capsys: pytest.CaptureFixture[str]) -> None:
    with socket.create_server(("127.0.0.1", 0)) as listener:
        done = threading.Event()
        refused: list[float] = []
        station = threading.Thread(target=_station, args=(listener, done, refused), daemon=True)
        station.start()
        load = Load(listener.getsockname()[1], 0, [25544], 60.0, 60.0, watchers=0, streams=0)
        poller = threading.Thread(target=load._poll_status, daemon=True)
        poller.start()
        try:
            wait_for(lambda: refused and any(s.at > refused[0] + 0.2 for s in load.links), 30.0,
                     lambda: f"a STATUS answer after the refusal; {len(load.links)} answers so far")
            assert poller.is_alive()
            assert all(s.rotor == "ok" and s.radio == "ok" for s in load.links)  # no refusal taken for an answer
            reasons = [why for _, why in load.status_failed]
            assert len(reasons) == load.status_failures == 2, reasons
            assert reasons[0].startswith("TimeoutError"), reasons
            assert "ERROR the station serves" in reasons[1], reasons
            assert "STATUS sample failed (TimeoutError" in capsys.readouterr().err  # said at once
        finally:
            load.stop.set()
            done.set()
            poller.join(10.0)
