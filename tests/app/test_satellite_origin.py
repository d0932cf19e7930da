"""Which satellite a station starts with, and why (issue 25 item 7): a choice saved while running wins over
``[server] satellite`` only while that setting is unchanged, and the station says which won, at start and
in STATUS (``satellite_from``)."""

from __future__ import annotations

import json

from nfwserver.app.station import Station
from nfwserver.clock import VirtualClock
from nfwserver.config.loader import load_config
from nfwserver.fake_dde import FakeDdeSystem
from nfwserver.tcp.protocol import NovaTcpProtocol
from nfwserver.tcp.status_line import parse_status
from tests.app.headless_run import serve_once
from tests.dde.conftest import ISS_PASS


def _start(tmp_path, configured: int, saved: dict | None, capsys) -> tuple[str, dict[str, str]]:
    """Run the station headless (printing its start-up notes), then read a station's STATUS line."""
    state = tmp_path / "state.json"
    path = tmp_path / "station.toml"
    path.write_text(f'[observer]\nlocation = "JO02ae"\n[server]\nsatellite = {configured}\n'
                    f'state_file = "{state}"\n')
    config = load_config(str(path))
    if saved is not None:
        state.write_text(json.dumps(saved))
    assert serve_once(config, tmp_path) == 0
    err = capsys.readouterr().err
    if saved is not None:
        state.write_text(json.dumps(saved))  # as before the run (the run saved its own choice)
    else:
        state.unlink(missing_ok=True)
    station = Station(config, VirtualClock(ISS_PASS.aos), transport=FakeDdeSystem().server_transport())
    station.start()
    try:
        line = NovaTcpProtocol(station.core).status_line()
        status = parse_status(line)
        status["hint"] = station.selection_note
    finally:
        station.stop()
    assert f"nfwserver: {station.selection_note}" in err
    return err, status


def test_a_saved_choice_wins_while_the_configuration_is_unchanged_and_says_so(tmp_path, capsys) -> None:
    err, status = _start(tmp_path, 25544, {"satellite": 7530, "configured": 25544}, capsys)
    assert status["satellite"] == "7530" and status["satellite_from"] == "saved-state"
    assert "satellite 7530: restored from" in status["hint"] and "saved choice wins" in status["hint"]


def test_a_changed_configuration_beats_the_saved_choice_and_says_so(tmp_path, capsys) -> None:
    err, status = _start(tmp_path, 25544, {"satellite": 7530, "configured": 43017}, capsys)
    assert status["satellite"] == "25544" and status["satellite_from"] == "config"
    assert "replaces the saved choice 7530" in status["hint"]


def test_without_saved_state_the_configuration_is_named(tmp_path, capsys) -> None:
    err, status = _start(tmp_path, 25544, None, capsys)
    assert status["satellite_from"] == "config" and "satellite 25544: from [server] satellite" in status["hint"]


def test_a_choice_made_after_the_last_tick_is_saved_at_stop_and_restored(tmp_path) -> None:
    """#34 item 4: ``SAT=`` over TCP answered ``OK``, then the station stops before its next tick (the virtual
    clock is not advanced): the saver wrote the last tick's sample, so the choice was lost."""
    from tests.tcp.conftest import LineClient

    state = tmp_path / "state.json"
    path = tmp_path / "station.toml"
    path.write_text(f'[observer]\nlocation = "JO02ae"\n[server]\nsatellite = 25544\nstate_file = "{state}"\n'
                    '[tcp]\nenabled = true\nport = 0\n')
    config = load_config(str(path))
    station = Station(config, VirtualClock(ISS_PASS.aos), transport=FakeDdeSystem().server_transport())
    station.start()
    try:
        assert station.tcp is not None
        client = LineClient(station.tcp.address)
        try:
            client.read_line()
            assert client.ask("SAT=7530") == "OK"
        finally:
            client.close()
    finally:
        station.stop()
    saved = json.loads(state.read_text())
    assert (saved["satellite"], saved["configured"], saved["autotrack"]) == (7530, 25544, False)
    again = Station(config, VirtualClock(ISS_PASS.aos), transport=FakeDdeSystem().server_transport())
    again.start()
    try:
        assert again.core.state.catalog_number == 7530
        assert again.core.selected_by == "saved-state"
    finally:
        again.stop()


def test_a_saved_state_that_only_repeats_the_configuration_is_not_called_a_choice(tmp_path, capsys) -> None:
    """#34 item 10: the saver records the configured satellite too, so the next start said "restored ...
    (chosen while running)" of a satellite nobody chose."""
    err, status = _start(tmp_path, 25544, {"satellite": 25544, "configured": 25544}, capsys)
    assert status["satellite"] == "25544" and status["satellite_from"] == "config"
    assert status["hint"] == "satellite 25544: from [server] satellite"
    assert "chosen while running" not in err
