"""The web page's pass list with the whole catalog as favourites: the search runs on the board's own thread
while the publish loop ticks, frames go out and the HTTP server answers."""

from __future__ import annotations

import sys

from nfwserver.web.pass_board import PassBoard
from tests.conftest import DATA
from tests.web.conftest import config_text, start_station


def _searching(board: PassBoard) -> bool:
    """True while the board's thread is inside the pass search (read from its Python stack)."""
    thread = board._thread
    frame = sys._current_frames().get(thread.ident) if thread is not None and thread.ident else None
    while frame is not None:
        if frame.f_code.co_name == "find_passes":
            return True
        frame = frame.f_back
    return False


def test_a_whole_catalog_pass_list_never_holds_the_station_back() -> None:
    numbers = [int(line[2:7]) for line in (DATA / "active.txt").read_text().splitlines()[1::3]]
    assert len(numbers) > 15000
    web = start_station(config_text(DATA / "active.txt", favourites=str(numbers)))
    try:
        assert web.station.web is not None
        server, board, core = web.station.web, web.station.web.board, web.station.core
        answered = ticked = framed = 0
        while board.version == 0:  # until the first whole-catalog search has finished
            if not _searching(board):
                web.advance(0.2)
                continue
            sample, frames = core.tracker.last_sample, server.stats.frames
            state = web.get("/api/state")  # the HTTP server answers
            web.advance(0.2)  # the publisher ticks ...
            if _searching(board):  # ... all while the search still runs
                answered += state["now"]["nova"] != ""
                ticked += core.tracker.last_sample is not sample
                framed += server.stats.frames > frames
        assert answered >= 3 and ticked >= 3 and framed >= 3, (answered, ticked, framed)
        passes = web.get("/api/passes")
        assert passes["version"] >= 1 and len(passes["passes"]) > 0
    finally:
        web.station.stop()
