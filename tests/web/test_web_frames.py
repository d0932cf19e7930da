"""Frames and the pass board: built only for a page, a failing pass search backs off and shows, a version is
never ahead of its result, a reload's favourites reach the page at once."""

from __future__ import annotations

import json
import logging
import sys
import threading
from datetime import timedelta

from nfwserver.clock import VirtualClock
from nfwserver.config.loader import parse_config
from nfwserver.core.station_core import StationCore
from nfwserver.web.pass_board import RETRY_FIRST_S, PassBoard
from tests.dde.conftest import CATALOG, ISS_PASS, OBSERVER
from tests.web.conftest import config_text, start_station, wait_for
from tests.web.web_helpers import connect, running_web


def test_frames_are_built_only_while_a_page_is_connected() -> None:
    """6ca6bee built ten frames a second with no browser connected."""
    with running_web() as (core, web):
        clock = core.clock
        assert isinstance(clock, VirtualClock)
        for _ in range(20):
            core.tick(clock.now())
            wait_for(lambda: not web._ticked.is_set(), what="the frame thread's round for this tick")
            clock.advance(0.2)
        assert web.stats.frames == 0
        with connect(web) as page:
            page.sendall(b"GET /api/stream HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n")
            wait_for(lambda: web.stats.streams == 1 and web.stats.frames >= 1, what="a frame for the page")
            assert b"event: state" in _read_until(page, b"event: state")
            built = web.stats.frames
            for _ in range(5):
                core.tick(clock.now())
                clock.advance(0.2)
            wait_for(lambda: web.stats.frames > built, what="frames while the page is connected")
        wait_for(lambda: web.stats.streams == 0, what="the page gone")
        quiet = web.stats.frames
        for _ in range(10):
            core.tick(clock.now())
            clock.advance(0.2)
        assert web.stats.frames <= quiet + 1  # at most the one that was under way
        state = json.loads(_get_state(web))
        assert state["now"]["satellite"]["catalog_number"] == 25544  # /api/state builds its own


def _read_until(sock, marker: bytes) -> bytes:
    got = b""
    while marker not in got:
        chunk = sock.recv(65536)
        if not chunk:
            break
        got += chunk
    return got


def _get_state(web) -> bytes:
    from tests.web.web_helpers import body, exchange

    return body(exchange(web, b"GET /api/state HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n"))


def _board(favourites):
    clock = VirtualClock(ISS_PASS.aos + timedelta(seconds=200))
    core = StationCore(CATALOG, OBSERVER, clock, satellite=25544, rate_hz=5.0)
    return clock, PassBoard(core.state, clock, favourites)


def test_a_failing_pass_search_backs_off_shows_and_logs_once(caplog) -> None:
    """6ca6bee retried every second once its first pass was over, with a traceback each time."""
    broken = threading.Event()
    calls = []

    def favourites():
        calls.append(1)
        if broken.is_set():
            raise RuntimeError("the favourites cannot be read")
        return (25544,)

    clock, board = _board(favourites)
    assert board.step() and board.result()["passes"] and not board.result().get("error")
    los = board._first_los
    assert los is not None
    broken.set()
    caplog.set_level(logging.DEBUG, "nfwserver.web")
    calls.clear()
    seconds = int((los - clock.now()).total_seconds()) + 60
    for _ in range(seconds):  # the board thread's rounds, one a second, past the first pass's LOS
        clock.advance(1.0)
        board.step()
    after_los = 60
    assert 1 <= len(calls) <= 1 + after_los // RETRY_FIRST_S, len(calls)  # 5, 10, 20, 40 s apart: 4 at most
    warnings = [r for r in caplog.records if r.levelno >= logging.WARNING]
    assert len(warnings) == 1 and "the pass search failed" in warnings[0].getMessage()
    assert all(r.exc_info is None for r in warnings)  # no traceback above DEBUG
    shown = json.loads(board.encoded())
    assert "the favourites cannot be read" in shown["error"] and shown["version"] == board.version
    broken.clear()
    for _ in range(130):  # the next retry, whatever its back-off, succeeds and clears the fault
        clock.advance(1.0)
        if board.step() and board.result()["error"] is None:
            break
    assert board.result()["error"] is None and json.loads(board.encoded())["error"] is None
    assert any("works again" in r.getMessage() for r in caplog.records)


def test_a_version_is_never_published_before_its_result() -> None:
    """6ca6bee bumped ``version`` before its encoded result: a page that read the new version fetched the
    old result and kept it (for up to 120 s)."""
    clock, board = _board(lambda: tuple(range(1, 80)))
    stop = threading.Event()
    behind = []

    def reader() -> None:
        while not stop.is_set():
            version = board.version
            served = json.loads(board.encoded())["version"]
            if served < version:
                behind.append((version, served))

    switching = sys.getswitchinterval()
    sys.setswitchinterval(1e-6)  # let the reader run between any two steps of a publication
    thread = threading.Thread(target=reader)
    thread.start()
    try:
        for _ in range(15):
            board.compute()
    finally:
        stop.set()
        thread.join()
        sys.setswitchinterval(switching)
    assert not behind, behind[:5]


def test_a_favourites_change_from_a_reload_reaches_the_page_at_once() -> None:
    web = start_station(config_text(favourites="[25544]"))
    try:
        assert web.station.web is not None
        board = web.station.web.board
        wait_for(lambda: board.version >= 1, what="the first pass list")
        assert {p["catalog_number"] for p in web.get("/api/passes")["passes"]} <= {25544}
        web.station.apply_config(parse_config(config_text(favourites="[25544, 694, 733, 877, 2802, 3230]")))
        # the station's clock stands still from here: only the reload can make the board compute
        wait_for(lambda: {p["catalog_number"] for p in web.get("/api/passes")["passes"]} - {25544},
                 what="the new favourites' passes")
    finally:
        web.station.stop()
