"""Device faults (issue 18 items 5 and 10): Hamlib peers on real loopback sockets that answer
non-finite, out-of-range or overlong values.  Such a reply is refused, counted as a device fault,
never becomes a position or a frequency, and a peer that keeps misbehaving is reported once and
then summarised, not once per tick."""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Iterator
from datetime import datetime, timezone

import pytest

from nfwserver.channels.channel import Channel
from nfwserver.clock import VirtualClock
from nfwserver.radio.backend import RadioError
from nfwserver.radio.rigctld_backend import RigctldBackend
from nfwserver.radio.tuning import DopplerTuner
from nfwserver.rotor.backend import RotorError
from nfwserver.rotor.geometry import RotorGeometry
from nfwserver.rotor.kct_driver import KctDriver
from nfwserver.rotor.rotctld_backend import RotctldBackend
from tests.hamlib_peer import ScriptedPeer

GEOMETRY = RotorGeometry(0.0, 450.0, 0.0, 90.0)


@pytest.fixture
def peer() -> Iterator[Callable[[Callable[[str, int], bytes]], ScriptedPeer]]:
    peers: list[ScriptedPeer] = []

    def start(answer: Callable[[str, int], bytes]) -> ScriptedPeer:
        peers.append(ScriptedPeer(answer))
        return peers[-1]

    yield start
    for p in peers:
        p.close()


def _clock() -> VirtualClock:
    return VirtualClock(datetime(2026, 5, 1, tzinfo=timezone.utc))


@pytest.mark.parametrize("reply", [b"nan\n34.0\n", b"inf\n34.0\n", b"10.0\n-inf\n", b"1e308\n34.0\n",
                                   b"10.0\n500.0\n", b"-90.0\n34.0\n", b"ten\n34.0\n"])
def test_rotctld_non_finite_or_out_of_range_positions_are_device_faults(peer, reply: bytes) -> None:
    p = peer(lambda cmd, n: reply if cmd == "p" else b"RPRT 0\n")
    backend = RotctldBackend(_clock(), GEOMETRY, port=p.port, timeout_s=2.0)
    with pytest.raises(RotorError, match="makes no sense|not a finite position"):
        backend.get_position()
    assert backend.connection.faults == 1
    driver = KctDriver(_clock(), backend, GEOMETRY)
    assert driver.read_position() is None and driver.rotor_position() is None
    driver.status()  # never raises on a bad reply


def test_a_70_kb_unterminated_line_then_normal_replies_never_yields_a_bogus_position(peer) -> None:
    def answer(cmd: str, n: int) -> bytes:
        if cmd != "p":
            return b"RPRT 0\n"
        return b"9" * 70_000 if n == 1 else b"10.000000\n34.000000\n"

    p = peer(answer)
    backend = RotctldBackend(_clock(), GEOMETRY, port=p.port, timeout_s=2.0)
    positions, errors = [], 0
    for _ in range(5):
        try:
            positions.append(backend.get_position())
        except RotorError:
            errors += 1
    assert errors == 1 and backend.connection.faults == 1
    assert positions == [(10.0, 34.0)] * 4  # the junk never leaks into a later reply


@pytest.mark.parametrize("reply", [b"inf\n", b"nan\n", b"1e999\n", b"-145000000\n", b"12\n", b"4e12\n"])
def test_rigctld_non_finite_or_out_of_range_frequencies_are_device_faults(peer, reply: bytes) -> None:
    p = peer(lambda cmd, n: reply if cmd == "f" else b"RPRT 0\n")
    backend = RigctldBackend(_clock(), port=p.port, timeout_s=2.0)
    with pytest.raises(RadioError, match="not a frequency"):
        backend.get_rx_frequency()
    assert backend.connection.faults == 1
    tuner = DopplerTuner(Channel("ISS", 437_800_000, 145_990_000), backend, clock=_clock())
    assert tuner.update(0.0) is not None  # first update sends, reads nothing back
    assert tuner.update(0.1) is None and "not a frequency" in (tuner.last_error or "")  # knob read refused


def test_a_value_where_rprt_was_due_and_rprt_where_a_value_was_due_are_faults(peer) -> None:
    p = peer(lambda cmd, n: b"RPRT 0\n" if cmd == "p" else b"145000000\n")
    backend = RotctldBackend(_clock(), GEOMETRY, port=p.port, timeout_s=2.0)
    with pytest.raises(RotorError):
        backend.get_position()
    with pytest.raises(RotorError):
        backend.set_position(10.0, 10.0)
    assert backend.connection.faults == 2


def _device_records(caplog) -> list[logging.LogRecord]:
    return [r for r in caplog.records if r.name.startswith("nfwserver") and r.levelno >= logging.WARNING]


def test_a_garbage_rotctld_polled_at_50_hz_is_reported_once_then_summarised(peer, caplog) -> None:
    p = peer(lambda cmd, n: b"\x00\xff garbage\n\x01\n" if cmd == "p" else b"RPRT 0\n")
    clock = _clock()
    driver = KctDriver(clock, RotctldBackend(clock, GEOMETRY, port=p.port, timeout_s=2.0), GEOMETRY)
    driver.set_target(20.0, 10.0)
    caplog.set_level(logging.INFO, logger="nfwserver")
    for _ in range(50 * 150):  # 150 s of 50 Hz ticks on the virtual clock
        driver.service()
        clock.advance(0.02)
    records = _device_records(caplog)
    # Each kind (the connection's fault, the driver's failed read, the stall it announces) is written
    # first and then at most once a minute with a count: at most 3 lines each over 150 s, not 7,500.
    def kind(r: logging.LogRecord) -> str:  # the logger and the start of the message's template
        return f"{r.name}: {str(r.msg)[:20]}"

    per_kind = {k: sum(kind(r) == k for r in records) for k in {kind(r) for r in records}}
    assert 2 <= len(per_kind) <= 8 and all(n <= 3 for n in per_kind.values()), per_kind
    assert any("more like this" in r.getMessage() for r in records)
    assert driver.backend.connection.faults == 50 * 150  # every bad reply still counted


def test_a_radio_that_keeps_refusing_is_reported_once_then_summarised(peer, caplog) -> None:
    p = peer(lambda cmd, n: b"RPRT -9\n")
    clock = _clock()
    tuner = DopplerTuner(Channel("ISS", 437_800_000, 145_990_000), RigctldBackend(clock, port=p.port), clock=clock)
    caplog.set_level(logging.INFO, logger="nfwserver")
    for k in range(50 * 70):
        assert tuner.update(k * 1e-4) is None
        clock.advance(0.02)
    records = _device_records(caplog)
    assert len(records) == 2 and "more like this" in records[1].getMessage()
    assert math.isclose(float(records[1].getMessage().split("(")[-1].split()[0]), 50 * 60 - 1, abs_tol=2)
