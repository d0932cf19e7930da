"""PREDICT UDP inside a whole station: a taken port, RELOAD_TLE floods and slow element sites, exposure warnings.

Issue 18 items 7, 8 and 15; real UDP and HTTP on 127.0.0.1, the station on a VirtualClock.
"""

from __future__ import annotations

import http.server
import logging
import socket
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass, field

import pytest

from nfwserver.app.station import Station
from nfwserver.cli import main
from nfwserver.clock import VirtualClock
from nfwserver.config.loader import parse_config
from nfwserver.fake_dde import FakeDdeSystem
from tests.conftest import DATA, advance_until
from tests.dde.conftest import ISS_PASS


@dataclass
class SlowSite:
    """An element site on 127.0.0.1 that holds every answer until ``release`` is set."""

    url: str
    release: threading.Event = field(default_factory=threading.Event)
    hits: list[float] = field(default_factory=list)
    served: list[float] = field(default_factory=list)


@pytest.fixture
def slow_site() -> Iterator[SlowSite]:
    body = (DATA / "visual.txt").read_bytes()
    site = SlowSite("")

    class Handler(http.server.BaseHTTPRequestHandler):
        def do_GET(self) -> None:
            site.hits.append(time.monotonic())
            site.release.wait(30.0)
            self.send_response(200)
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)
            site.served.append(time.monotonic())

        def log_message(self, *args) -> None:
            pass

    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    site.url = f"http://127.0.0.1:{server.server_address[1]}/visual.txt"
    yield site
    site.release.set()
    server.shutdown()
    server.server_close()


def udp_client() -> socket.socket:
    client = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    client.settimeout(5.0)
    return client


def test_run_says_one_sentence_when_the_predict_port_is_taken(tmp_path, capsys) -> None:
    # Issue 18.7: "PREDICT port already in use -> traceback at start; make it one sentence."
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as squatter:
        squatter.bind(("127.0.0.1", 0))
        port = squatter.getsockname()[1]
        cfg = tmp_path / "c.toml"
        cfg.write_text(f'[observer]\nlocation = "JO02ae"\n[dialects]\npredict_udp = true\npredict_port = {port}\n')
        assert main(["run", "--headless", "--duration", "0.2", "--config", str(cfg)]) == 1
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if line.strip() and not line.startswith("nfwserver: logging to ")]
    assert len(lines) == 1 and "Traceback" not in err, err
    assert lines[0] == (f"nfwserver: cannot start the station: PREDICT UDP port {port} is already in use (by another "
                        "program or another station); set [dialects] predict_port to another port")


def test_a_non_loopback_predict_host_is_warned_about_at_start(caplog) -> None:
    # Issue 18.15: "Any non-loopback bind logs a warning at start". 192.0.2.1 (TEST-NET-1) is not ours,
    # so the bind fails too -- nothing is exposed by this test.
    config = parse_config('[observer]\nlocation = "JO02ae"\n[elements]\nuse_bundled = false\n'
                          '[dialects]\npredict_udp = true\npredict_host = "192.0.2.1"\npredict_port = 0\n')
    station = Station(config, VirtualClock(ISS_PASS.tca), transport=FakeDdeSystem().server_transport())
    with pytest.raises(OSError, match=r"PREDICT UDP \[dialects\] predict_host 192.0.2.1 is not an address of this "
                       r"machine \(set \[dialects\] predict_host\)"):
        station.start()
    station.stop()
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert any("predict_host" in w and "192.0.2.1" in w and "reachable from other hosts" in w for w in warnings)


def test_reload_tle_floods_are_coalesced_and_never_block_get_sat(slow_site, tmp_path, caplog) -> None:
    # Issue 18.8: a slow URL blocked GET_SAT for 4.9 s; 50 datagrams -> 50 HTTP GETs; 2,000 -> 182 KB of log.
    caplog.set_level(logging.INFO, logger="nfwserver")
    keps = tmp_path / "keps.txt"
    keps.write_text((DATA / "visual.txt").read_text())
    config = parse_config(f'[observer]\nlocation = "52.2053,0.1218,20"\n'
                          f'[elements]\nfiles = ["{keps}"]\nurls = ["{slow_site.url}"]\nuse_bundled = false\n'
                          '[dialects]\npredict_udp = true\npredict_port = 0\n')
    clock = VirtualClock(ISS_PASS.tca)
    station = Station(config, clock, transport=FakeDdeSystem().server_transport())
    station.start()
    try:
        address = station.predict.address
        with udp_client() as client:
            assert advance_until(clock, lambda: len(slow_site.hits) == 1)  # the first fetch hangs on the site
            for _ in range(50):
                client.sendto(b"RELOAD_TLE", address)
                began = time.monotonic()
                client.sendto(b"GET_SAT 25544", address)
                replies = {client.recvfrom(2048)[0] for _ in range(2)}
                assert b"" in replies and any(r.startswith(b"ISS (ZARYA)\n") for r in replies)
                assert time.monotonic() - began < 0.5
            slow_site.release.set()
            assert advance_until(clock, lambda: station.refresher.fetches == 2 and len(slow_site.served) == 2,
                                 step_s=1.0)
            advance_until(clock, lambda: False, step_s=5.0, limit_s=600.0)  # ten more minutes: nothing more
            assert len(slow_site.hits) == 2 and station.refresher.fetches == 2
            client.sendto(b"GET_SAT 25544", address)
            assert client.recvfrom(2048)[0].startswith(b"ISS (ZARYA)\n")
    finally:
        slow_site.release.set()
        station.stop()
    refreshed = [r for r in caplog.records if r.getMessage().startswith("elements refreshed")]
    assert len(refreshed) == 2  # one line per actual reload, none per request
    assert not [r for r in caplog.records if r.levelno >= logging.WARNING]
