"""A forged or garbled session state file (the autotrack mode kept across restarts) never stops the station:
each gives one warning naming the file and is read as "no saved state"; a reason that would carry line breaks
or a page of text into the log, STATUS and the page is refused at the door."""

from __future__ import annotations

import json
import logging
import os
import sys

import pytest

from nfwserver.app.session_state import MAX_REASON_CHARS, MAX_STATE_BYTES, SessionState, StateFile

FORGED = {
    "nested arrays deeper than the interpreter's stack": "[" * 100_000,
    "nested objects deeper than the interpreter's stack": '{"a":' * 100_000,
    "a list": "[1, 2]",
    "a file larger than any state": json.dumps({"satellite": 25544, "pad": " " * MAX_STATE_BYTES}),
}


@pytest.mark.parametrize("text", FORGED.values(), ids=list(FORGED))
def test_a_forged_state_file_is_one_warning_and_no_saved_state(tmp_path, caplog, text: str) -> None:
    path = tmp_path / "state.json"
    path.write_text(text, encoding="utf-8")
    with caplog.at_level(logging.WARNING):
        state = StateFile(path).load()
    assert state == SessionState()
    warnings = [r for r in caplog.records if r.levelno >= logging.WARNING]
    assert len(warnings) == 1 and str(path) in warnings[0].getMessage()
    assert len(warnings[0].getMessage()) < 400



def test_a_sane_file_loads_whole(tmp_path) -> None:
    path = tmp_path / "state.json"
    path.write_text(json.dumps({"satellite": 25544, "configured": None, "autotrack": False,
                                "autotrack_off": "AUTO OFF from tcp 127.0.0.1:5000", "autotrack_enabled": True}))
    assert StateFile(path).load() == SessionState(25544, None, False, "AUTO OFF from tcp 127.0.0.1:5000", True)


@pytest.mark.skipif(sys.platform == "win32", reason="no FIFOs")
def test_a_fifo_in_place_of_the_state_file_is_one_warning_not_a_hang(tmp_path, caplog) -> None:
    """A plain open() of a FIFO waits for a writer for ever: the station would never start."""
    path = tmp_path / "state.json"
    os.mkfifo(path)
    with caplog.at_level(logging.WARNING):
        assert StateFile(path).load() == SessionState()
    assert len([r for r in caplog.records if r.levelno >= logging.WARNING]) == 1


CLEANED = {
    "a reason with a line break": ("x\r\nOK satellite=evil", "x OK satellite=evil"),
    "a reason with an escape sequence": ("\x1b[2Jgone", "[2Jgone"),
    "a reason of 5,000 characters": ("x" * 5000, "x" * MAX_REASON_CHARS),
}


@pytest.mark.parametrize(("reason", "kept"), CLEANED.values(), ids=list(CLEANED))
def test_a_forged_reason_is_one_warning_and_kept_cut_and_cleaned(tmp_path, caplog, reason: str, kept: str) -> None:
    """The reason autotrack was off goes to the log, STATUS and the page: read back as one printable line."""
    path = tmp_path / "state.json"
    path.write_text(json.dumps({"satellite": 25544, "autotrack": False, "autotrack_off": reason}))
    with caplog.at_level(logging.WARNING):
        state = StateFile(path).load()
    assert state == SessionState(25544, None, False, kept)
    assert len([r for r in caplog.records if r.levelno >= logging.WARNING]) == 1


def test_a_reason_naming_a_long_state_file_path_is_kept_whole(tmp_path) -> None:
    """After a restart the reason names the state file; a deep (Windows: 260 characters) path still fits."""
    reason = "AUTO OFF from tcp 127.0.0.1:5000 (before the restart, kept in C:\\" + "d\\" * 130 + "state.json)"
    path = tmp_path / "state.json"
    path.write_text(json.dumps({"autotrack": False, "autotrack_off": reason}))
    assert StateFile(path).load().autotrack_off == reason

