"""The web listener without a browser: bounds, refusals, the command port, the configuration, ``run --web``."""

from __future__ import annotations

import socket
import threading
import time
import urllib.request
from datetime import timedelta

import pytest

from nfwserver.cli.run_command import RunPlan, serve, with_web
from nfwserver.clock import VirtualClock
from nfwserver.config.loader import ConfigError, parse_config
from nfwserver.config.schema import WebConfig
from nfwserver.core.station_core import StationCore
from nfwserver.fake_dde import FakeDdeSystem
from nfwserver.web import WebServer
from nfwserver.web.hub import FrameHub
from tests.dde.conftest import CATALOG, ISS_PASS, OBSERVER
from tests.waiting import wait_for
from tests.web.conftest import TOKEN, config_text, start_station


def test_a_browser_that_stops_reading_is_dropped_and_never_delays_a_tick() -> None:
    clock = VirtualClock(ISS_PASS.aos + timedelta(seconds=200))
    core = StationCore(CATALOG, OBSERVER, clock, satellite=25544, rate_hz=5.0)
    core.set_feed(True)
    web = WebServer(core, WebConfig(enabled=True, port=0), io_timeout_s=0.5, send_buffer_bytes=4096)
    web.start()
    try:
        assert web.address is not None
        stalled = socket.socket()
        stalled.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        stalled.connect(web.address)
        stalled.sendall(b"GET /api/stream HTTP/1.0\r\n\r\n")  # and never reads again
        wait_for(lambda: web.stats.streams == 1, what="the stream to open")
        took: list[float] = []

        def tick() -> int:
            began = time.perf_counter()
            core.tick(clock.now())  # the publisher's work, listeners included
            took.append(time.perf_counter() - began)
            clock.advance(0.2)
            return web.stats.dropped

        wait_for(tick, 20.0, "the stalled stream to be dropped")
        assert web.stats.dropped == 1 and web.stats.streams == 0
        assert max(took) < 0.05, max(took)  # a tick never waited for the stalled browser (its writes time out in 0.5 s)
        with urllib.request.urlopen(web.url + "api/state", timeout=5) as reply:  # the others are served on
            assert reply.status == 200
        stalled.close()
    finally:
        web.stop()


def test_peers_outside_allow_are_closed_and_recorded() -> None:
    clock = VirtualClock(ISS_PASS.aos)
    core = StationCore(CATALOG, OBSERVER, clock, satellite=25544)
    web = WebServer(core, WebConfig(enabled=True, port=0, allow=("10.0.0.0/8",)))
    web.start()
    try:
        with pytest.raises(OSError):
            urllib.request.urlopen(web.url + "api/state", timeout=5).read()
        assert web.stats.refused == 1
        refusals = [e for e in core.events.recent() if e.text == "connection refused: not in [web] allow"]
        assert len(refusals) == 1 and refusals[0].client == "web 127.0.0.1"
    finally:
        web.stop()


def test_connections_are_bounded() -> None:
    clock = VirtualClock(ISS_PASS.aos)
    core = StationCore(CATALOG, OBSERVER, clock, satellite=25544)
    web = WebServer(core, WebConfig(enabled=True, port=0), max_clients=2)
    web.start()
    held = []
    try:
        assert web.address is not None
        for _ in range(2):
            sock = socket.create_connection(web.address)
            sock.sendall(b"GET /api/stream HTTP/1.0\r\n\r\n")
            held.append(sock)
        wait_for(lambda: web.stats.streams == 2, what="two streams")
        with pytest.raises(OSError):
            urllib.request.urlopen(web.url + "api/state", timeout=5).read()
        assert web.stats.refused == 1
    finally:
        for sock in held:
            sock.close()
        web.stop()


def test_control_requests_are_checked_whole_before_the_core_sees_them() -> None:
    web = start_station(config_text())
    try:
        core = web.station.core
        assert web.post({"command": "TRACK ON"})[0] == 403  # no token
        assert web.post({"command": "TRACK ON", "token": TOKEN + "x"})[0] == 403
        assert web.post({"command": "TRACK ON\nTUNE OFF", "token": TOKEN})[0] == 400  # one line only
        status, body = web.post({"command": "QUIT", "token": TOKEN})  # a TCP session command, not the station's
        assert status == 400 and "not a station command" in body["message"]
        assert web.post(["TRACK ON"])[0] == 400
        snap = core.state.snapshot()
        assert not snap.tracking and snap.feed_on
        status, body = web.post({"command": "track on", "token": TOKEN})
        assert status == 200 and body["ok"] and core.state.snapshot().tracking
        assert body["message"].startswith("TRACK ON with no rotor configured")  # this station has no rotor
        status, body = web.post({"command": "SAT=ISS (ZARYA)", "token": TOKEN})  # by name, as on TCP
        assert status == 200 and core.state.catalog_number == 25544
        status, body = web.post({"command": "SAT=1", "token": TOKEN})
        assert status == 409 and "not in the catalog" in body["message"]
        status, body = web.post({"command": "PARK", "token": TOKEN})  # a rotor command; this station has none
        assert (status, body["message"]) == (409, "no rotor is configured")
        help_ = web.get("/api/help")
        assert [c["usage"] for c in help_["commands"]] == ["TUNE ON|OFF", "TRACK ON|OFF", "SAT=<catalog number>",
                                                           "ANTAZ=<degrees>", "ANTEL=<degrees>", "DOPPLER ON|OFF",
                                                           "AUTO ON|OFF", "FLIP AUTO|ON|OFF", "PARK"]
    finally:
        web.station.stop()


def test_static_files_are_served_from_the_package_only() -> None:
    web = start_station(config_text(control=False))
    try:
        for path in ("/static/../server.py", "/static/%2e%2e/server.py", "/static/nothing.js", "/etc/passwd"):
            with pytest.raises(urllib.error.HTTPError) as refused:
                urllib.request.urlopen(web.url + path.lstrip("/"), timeout=5)
            assert refused.value.code == 404
        with urllib.request.urlopen(web.url, timeout=5) as page:
            assert "default-src 'self'" in page.headers["Content-Security-Policy"]
            assert b'data-testid="now-tracking"' in page.read()
        passes = web.get("/api/passes")
        assert passes["passes"] and passes["track"]["aos"] and len(passes["horizon"]) == 73
    finally:
        web.station.stop()


def test_hub_gives_the_newest_frame_and_wakes_waiters_on_close() -> None:
    hub = FrameHub()
    hub.publish(b"1")
    hub.publish(b"2")
    assert hub.wait_newer(0) == (2, b"2")  # a slow reader skips to the newest
    got = []
    waiter = threading.Thread(target=lambda: got.append(hub.wait_newer(2)))
    waiter.start()
    hub.close()
    waiter.join(5)
    assert got == [(2, None)]


def test_web_configuration() -> None:
    assert WebConfig() == WebConfig(enabled=False, host="127.0.0.1", port=8091, allow=("127.0.0.1/32", "::1/128"),
                                    hostnames=(), control=False, token=None)
    with pytest.raises(ConfigError, match=r"\[web\] token: required when control is on"):
        parse_config("[web]\ncontrol = true\n")
    short = parse_config('[web]\ncontrol = true\ntoken = "short"\n')  # loaded, with control off and one warning
    assert not short.web.control and any(w.startswith("[web] token: must be at least 8 characters")
                                         for w in short.warnings)
    exposed = parse_config('[web]\nenabled = true\nhost = "0.0.0.0"\nallow = ["192.168.1.0/24"]\n')
    assert any(w.startswith('[web] host = "0.0.0.0"') for w in exposed.warnings)
    assert not parse_config('[web]\nhost = "0.0.0.0"\n').warnings  # off: nothing listens
    assert any(w.startswith('[web] host = "0.0.0.0"') for w in with_web(parse_config('[web]\nhost = "0.0.0.0"\n'))
               .warnings)


def test_run_web_serves_the_dashboard_for_one_run_and_prints_its_url(tmp_path, capsys) -> None:
    config = with_web(parse_config(config_text(control=False).replace("enabled = true", "enabled = false")))
    clock = VirtualClock(ISS_PASS.aos)
    stop = threading.Event()
    plan = RunPlan(console=False, log_file=tmp_path / "nfw.log", clock=clock,
                   transport=FakeDdeSystem().server_transport(), stop=stop)
    urls: list[str] = []

    def drive() -> None:
        def printed() -> bool:
            return "web dashboard: http" in (tmp_path / "nfw.log").read_text() \
                if (tmp_path / "nfw.log").exists() else False
        wait_for(printed, what="the URL")
        line = next(line for line in (tmp_path / "nfw.log").read_text().splitlines() if "web dashboard: " in line)
        urls.append(line.split("web dashboard: ", 1)[1].strip())
        with urllib.request.urlopen(urls[0] + "api/state", timeout=5) as reply:
            assert reply.status == 200
        stop.set()

    driver = threading.Thread(target=drive)
    driver.start()
    assert serve(config, plan) == 0
    driver.join()
    assert urls and f"nfwserver: web dashboard: {urls[0]}" in capsys.readouterr().err


def test_a_newer_sample_is_framed_even_if_the_clock_then_stands_still() -> None:
    """The frame thread once measured its rate limit from the clock's time when it woke: woken late (under
    load), it took the next tick for one less than 0.1 s after its frame and waited 0.1 s of clock time for
    it; on a clock that then stood still, that newest sample was never framed and the page stayed one tick
    behind for good (the browser test flaked with it).  The limit is now measured between samples."""
    from dataclasses import replace

    clock = VirtualClock(ISS_PASS.aos + timedelta(seconds=200))
    core = StationCore(CATALOG, OBSERVER, clock, satellite=25544, rate_hz=5.0)
    core.set_feed(True)
    web = WebServer(core, WebConfig(enabled=True, port=0))
    web.start()
    assert web.address is not None
    page = socket.create_connection(web.address, timeout=10)  # frames are built while a page is connected
    try:
        page.sendall(b"GET /api/stream HTTP/1.0\r\n\r\n")
        wait_for(lambda: web.stats.streams == 1, what="the page's stream")
        first = core.tick(clock.now())  # the publisher's work, listeners included
        wait_for(lambda: web.stats.frames >= 2, what="the first tick's frame")
        seen = web.hub.seq
        # The clock stands still from here; the ticks below are what a publisher catching up delivers.
        web.on_tick(replace(first, time=first.time + timedelta(seconds=0.2), text="LATE AZ:1.0 EL:2.0 RR:0.0 AH:Y"))
        wait_for(lambda: web.hub.seq > seen, timeout_s=10.0, what="the late sample's frame")
        seen = web.hub.seq
        web.on_tick(replace(first, time=first.time + timedelta(seconds=0.4), text="NEWEST AZ:1.0 EL:2.0 RR:0.0 AH:Y"))
        wait_for(lambda: web.hub.seq > seen and b"NEWEST" in (web.hub.newest()[1] or b""), timeout_s=10.0,
                 what="the newest sample's frame, the clock standing still")
    finally:
        page.close()
        web.stop()
