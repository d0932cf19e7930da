"""Hostile input: Hamlib peers that answer garbage, truncate, hang or vanish; fuzzed configuration; log forging."""

from __future__ import annotations

import logging
import socket
import threading
import time
from collections.abc import Iterator

import pytest
from hypothesis import given
from hypothesis import strategies as st

from nfwserver.channels.channel import Channel
from nfwserver.clock import SystemClock
from nfwserver.config.loader import ConfigError, parse_config
from nfwserver.fake_dde import DdeError
from nfwserver.radio.backend import RadioError
from nfwserver.radio.rigctld_backend import RigctldBackend
from nfwserver.radio.tuning import DopplerTuner
from nfwserver.rotor.backend import RotorError
from nfwserver.rotor.geometry import RotorGeometry
from nfwserver.rotor.rotctld_backend import RotctldBackend
from tests.dde.conftest import make_station

BEHAVIOURS = {
    "garbage": b"\x00\xff not a number\n\x01\x02\n",
    "truncated": b"14580",
    "rprt-junk": b"RPRT banana\n",
    "huge": b"9" * 100_000,
    "silent": None,
    "close": b"",
}


@pytest.fixture
def hostile() -> Iterator[callable]:
    """Start a loopback TCP server with a given misbehaviour; returns its port."""
    servers = []

    def start(behaviour: str) -> int:
        listener = socket.socket()
        listener.bind(("127.0.0.1", 0))
        listener.listen()
        stop = threading.Event()

        def serve() -> None:
            listener.settimeout(0.1)
            while not stop.is_set():
                try:
                    conn, _ = listener.accept()
                except OSError:
                    continue
                reply = BEHAVIOURS[behaviour]
                try:
                    conn.recv(1024)
                    if reply:
                        conn.sendall(reply)
                    if reply is None:
                        stop.wait(3.0)  # never answer
                except OSError:
                    pass
                finally:
                    conn.close()

        thread = threading.Thread(target=serve, daemon=True)
        thread.start()
        servers.append((listener, stop, thread))
        return listener.getsockname()[1]

    yield start
    for listener, stop, thread in servers:
        stop.set()
        thread.join(2)
        listener.close()


@pytest.mark.parametrize("behaviour", sorted(BEHAVIOURS))
def test_bad_daemon_replies_become_clear_errors_quickly(hostile, behaviour) -> None:
    port = hostile(behaviour)
    radio = RigctldBackend(SystemClock(), port=port, timeout_s=0.3)
    rotor = RotctldBackend(SystemClock(), RotorGeometry.preset("overlap-450"), port=port, timeout_s=0.3)
    for call in (radio.get_rx_frequency, lambda: radio.set_rx_frequency(145_800_000)):
        started = time.monotonic()
        with pytest.raises(RadioError):
            call()
        assert time.monotonic() - started < 1.5
    with pytest.raises(RotorError):
        rotor.get_position()
    tuner = DopplerTuner(Channel("x", 145_800_000), RigctldBackend(SystemClock(), port=port, timeout_s=0.3))
    assert tuner.update(1.0) is None  # never raises into the caller
    assert tuner.last_error


_value = st.one_of(st.integers(-10**6, 10**6), st.floats(allow_nan=True), st.text(max_size=10), st.booleans(),
                   st.lists(st.integers(-400, 400), max_size=3))
_sections = st.sampled_from(["observer", "horizon", "elements", "server", "satellites", "radio", "rotor",
                             "dialects", "junk"])
_keys = st.sampled_from(["location", "points", "files", "urls", "rate_hz", "satellite", "names", "backend",
                         "port", "geometry", "threshold_deg", "dde", "predict_port", "refresh_hours", "x"])


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'
    if isinstance(v, float) and v != v:
        return "nan"
    if isinstance(v, list):
        return "[" + ", ".join(str(x) for x in v) + "]"
    return repr(v) if not isinstance(v, float) or abs(v) < 1e300 else "inf"


@given(st.lists(st.tuples(_sections, _keys, _value), max_size=8))
def test_fuzzed_configuration_is_accepted_or_refused_with_reasons(entries) -> None:
    sections: dict[str, dict[str, object]] = {}
    for s, k, v in entries:  # each section and key once, so that most files are valid TOML and reach validation
        sections.setdefault(s, {})[k] = v
    text = "".join(f"[{s}]\n" + "".join(f"{k} = {_toml_value(v)}\n" for k, v in keys.items())
                   for s, keys in sections.items())
    try:
        parse_config(text)
    except ConfigError as exc:
        # Refused with reasons, each one line naming the section and key of the file it is about (or the TOML).
        assert exc.problems
        named = tuple(f"[{s}] {k}:" for s, k, _ in entries) + tuple(f"[{s}]:" for s, _, _ in entries)
        for problem in exc.problems:
            assert problem.strip() and "\n" not in problem
            assert problem.startswith(("not valid TOML", *named)), problem


@given(st.text(max_size=500))
def test_random_text_configuration(text) -> None:
    # Accepted, or refused with at least one reason, each one printable line naming TOML or a section.
    try:
        parse_config(text)
    except ConfigError as exc:
        assert exc.problems
        for problem in exc.problems:
            assert problem.strip() and "\n" not in problem
            assert problem.startswith(("not valid TOML", "[")), problem


def test_pokes_cannot_forge_log_lines(caplog) -> None:
    caplog.set_level(logging.WARNING)
    station = make_station()
    conv = station.system.connect("NFW32", "NFW_DATA")
    with pytest.raises(DdeError):
        conv.poke("NFW_SERVER", "SAT=1\r\nINFO nfwserver: operator logged in\r\n")
    assert caplog.records
    for record in caplog.records:
        assert "\n" not in record.getMessage() and "\r" not in record.getMessage()
