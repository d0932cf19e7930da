"""``[server] satellite`` takes a name the way ``SAT=`` does (#34 item 10): resolved against the loaded
catalog at start, one sentence when it names no satellite or several; the state file still records the
catalog number.  (6ca6bee: "'ISS' is not a catalog number", and the station did not start.)"""

from __future__ import annotations

import json
import logging

import pytest

from nfwserver.app.station import Station
from nfwserver.cli import main
from nfwserver.clock import VirtualClock
from nfwserver.config.loader import load_config
from nfwserver.fake_dde import FakeDdeSystem
from nfwserver.tcp.protocol import NovaTcpProtocol
from nfwserver.tcp.status_line import parse_status
from tests.conftest import DATA
from tests.dde.conftest import ISS_PASS


def _station(tmp_path, satellite: str) -> tuple[Station, dict[str, str]]:
    state = tmp_path / "state.json"
    path = tmp_path / "station.toml"
    path.write_text(f'[observer]\nlocation = "JO02ae"\n[elements]\nfiles = ["{DATA / "visual.txt"}"]\n'
                    f'use_bundled = false\nstore = "none"\n[server]\nsatellite = {satellite}\nstate_file = "{state}"\n')
    station = Station(load_config(str(path)), VirtualClock(ISS_PASS.aos), transport=FakeDdeSystem().server_transport())
    station.start()
    return station, parse_status(NovaTcpProtocol(station.core).status_line())


@pytest.mark.parametrize("name", ['"ISS (ZARYA)"', '"iss"', '"oao 2"'])
def test_a_name_selects_the_satellite_it_names_and_the_state_file_keeps_the_number(tmp_path, name) -> None:
    station, status = _station(tmp_path, name)
    try:
        expected = next(s for s in station.catalog if json.loads(name).upper() in (s.dde_name.upper(),
                                                                                  s.name.upper()))
        assert station.core.state.catalog_number == expected.catalog_number
        assert status["satellite"] == str(expected.catalog_number) and status["satellite_from"] == "config"
        assert station.selection_note == f"satellite {expected.catalog_number}: from [server] satellite"
        assert station.saver is not None and station.saver.configured == expected.catalog_number
        station.core.tick()
    finally:
        station.stop()
    saved = json.loads((tmp_path / "state.json").read_text())
    assert saved["configured"] == expected.catalog_number  # a number, as the state file always held


def test_an_unknown_name_is_one_sentence_and_no_satellite(tmp_path, caplog) -> None:
    with caplog.at_level(logging.WARNING):
        station, status = _station(tmp_path, '"NO SUCH BIRD"')
    try:
        assert station.core.state.catalog_number is None and status["satellite"] == "-"
        note = station.selection_note
        assert note == ("[server] satellite 'NO SUCH BIRD' names no satellite in the loaded elements, so none is "
                        "selected (give its catalog number or its name as `nfwserver passes` lists it)")
        assert [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING] == [note]
    finally:
        station.stop()


def test_config_set_takes_a_name(tmp_path, capsys) -> None:
    path = tmp_path / "station.toml"
    path.write_text('[observer]\nlocation = "JO02ae"\n')
    assert main(["config", "set", "--config", str(path), "server.satellite", "ISS (ZARYA)"]) == 0
    assert load_config(str(path)).server.satellite == "ISS (ZARYA)"
    assert main(["config", "set", "--config", str(path), "server.satellite", "7530"]) == 0
    assert load_config(str(path)).server.satellite == 7530
