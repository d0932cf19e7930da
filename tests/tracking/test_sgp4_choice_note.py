"""The start-up sgp4 check's finding is a fact about the machine an operator cannot act on (#45 item 6: under
Wine every command began with "warning: sgp4's compiled TLE reader is wrong here"): it is logged at INFO,
so a command shows it only under ``-v``, and a station writes it into its log once at each start."""

from __future__ import annotations

import logging
from datetime import datetime, timezone

import pytest
import sgp4.api

from nfwserver.app import station as station_module
from nfwserver.app.station import Station
from nfwserver.clock import VirtualClock
from nfwserver.config.loader import parse_config
from nfwserver.fake_dde import FakeDdeSystem
from nfwserver.tracking.sgp4_selfcheck import Sgp4Choice, ensure_working_sgp4


def test_a_wrong_compiled_reader_is_a_note_not_a_warning(monkeypatch: pytest.MonkeyPatch,
                                                         caplog: pytest.LogCaptureFixture) -> None:
    if not sgp4.api.accelerated:
        pytest.skip("sgp4 has no compiled extension here")

    class WrongReader(sgp4.api.Satrec):  # what Wine 8.0 does: the mean motion read as 0
        @classmethod
        def twoline2rv(cls, line1: str, line2: str, whichconst: int = sgp4.api.WGS72) -> sgp4.api.Satrec:
            return super().twoline2rv(line1, line2[:52] + " 0.00000000" + line2[63:], whichconst)

    monkeypatch.setattr(sgp4.api, "Satrec", WrongReader)
    caplog.set_level(logging.DEBUG)
    choice = ensure_working_sgp4()
    assert choice.mode == "compiled-python-parser"
    assert [r.levelno for r in caplog.records if r.levelno >= logging.WARNING] == []
    notes = [r for r in caplog.records if "compiled TLE reader is wrong here" in r.getMessage()]
    assert len(notes) == 1 and notes[0].levelno == logging.INFO


def test_a_station_logs_the_machines_sgp4_once_at_start(monkeypatch: pytest.MonkeyPatch,
                                                        caplog: pytest.LogCaptureFixture) -> None:
    detail = "sgp4's compiled TLE reader is wrong here (error inf km): the test's stand-in"
    monkeypatch.setattr(station_module, "SGP4_CHOICE", Sgp4Choice("compiled-python-parser", detail))
    config = parse_config('[observer]\nlocation = "JO02ae"\n[elements]\nstore = "none"\n'
                          '[server]\nstate_file = "none"\n')
    station = Station(config, VirtualClock(datetime(2026, 11, 28, tzinfo=timezone.utc)),
                      transport=FakeDdeSystem().server_transport())
    caplog.set_level(logging.INFO)
    station.start()
    try:
        logged = [r for r in caplog.records if r.getMessage() == detail]
        assert len(logged) == 1 and logged[0].levelno == logging.INFO
    finally:
        station.stop()
