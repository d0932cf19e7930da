"""Shared test configuration: deterministic hypothesis, paths to shared data, Hamlib daemons."""

from __future__ import annotations

import http.server
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

from tests.hamlib_daemons import HamlibDaemon

settings.register_profile(
    "nfwserver", derandomize=True, deadline=None, suppress_health_check=[HealthCheck.too_slow]
)
settings.load_profile("nfwserver")

ROOT = Path(__file__).resolve().parent.parent
#: Element sets shipped with the tests (copied from ../shared/data, a fact-only CelesTrak snapshot).
DATA = ROOT / "tests" / "data"


@pytest.fixture(autouse=True)
def private_user_dirs(tmp_path_factory, monkeypatch) -> None:
    """Keep every test away from the real user's configuration, data and state directories."""
    base = tmp_path_factory.mktemp("home")
    for var in ("XDG_CONFIG_HOME", "XDG_DATA_HOME", "XDG_STATE_HOME", "XDG_CACHE_HOME"):
        monkeypatch.setenv(var, str(base / var.lower()))


@pytest.fixture
def rotctld() -> Iterator[HamlibDaemon]:
    """A running ``rotctld -m 1`` (dummy rotor) on a free loopback port."""
    with HamlibDaemon("rotctld") as daemon:
        yield daemon


@pytest.fixture
def rigctld() -> Iterator[HamlibDaemon]:
    """A running ``rigctld -m 1`` (dummy rig) on a free loopback port."""
    with HamlibDaemon("rigctld") as daemon:
        yield daemon


def advance_until(clock, predicate, step_s: float = 0.2, limit_s: float = 600.0, real_timeout_s: float = 20.0) -> bool:
    """Advance a :class:`VirtualClock` in ``step_s`` steps until ``predicate()`` holds.

    The station's threads wait on that clock, so each step lets them run; between steps the test
    yields the processor briefly (never a fixed sleep of seconds).  Returns the predicate's last value:
    False when ``limit_s`` of virtual time or ``real_timeout_s`` of real time ran out.
    """
    import time

    deadline = time.monotonic() + real_timeout_s
    advanced = 0.0
    while not predicate():
        if advanced >= limit_s or time.monotonic() > deadline:
            return bool(predicate())
        clock.advance(step_s)
        advanced += step_s
        time.sleep(0.002)
    return True


@pytest.fixture
def http_server() -> Iterator[str]:
    """Serves tests/data and a garbage file on 127.0.0.1 (ephemeral port)."""

    class Handler(http.server.SimpleHTTPRequestHandler):
        def __init__(self, *a, **k):
            super().__init__(*a, directory=str(DATA), **k)

        def log_message(self, *args):  # keep test output clean
            pass

    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{server.server_address[1]}"
    server.shutdown()
    server.server_close()
