"""Autotrack in the station (issue 43 items 3 and 5): ``AUTO ON|OFF`` in the command table, any accepted ``SAT=``
switching it off, STATUS showing it, the mode kept across a restart, ``simulate --config`` following it.

Real outputs on virtual time: Nova's DDE service on the in-process transport with an advise client, Nova's TCP
protocol (a real socket where the station runs whole).  What the schedule's satellite is at each instant comes
from ``nfwserver passes`` CSV and the rule's words (tests/autotrack/test_schedule_cli.py's oracle).
"""

from __future__ import annotations

import json
from datetime import datetime, timedelta, timezone
from pathlib import Path

import pytest

from nfwserver.app.autotrack_link import StationAutotrack
from nfwserver.app.station import Station
from nfwserver.cli import main
from nfwserver.clock import VirtualClock
from nfwserver.config.loader import load_config, parse_config
from nfwserver.core.publisher import run_virtual
from nfwserver.core.station_core import StationCore
from nfwserver.dde.nova_service import NovaDdeService
from nfwserver.fake_dde import FakeDdeSystem
from nfwserver.tcp.protocol import NovaTcpProtocol
from nfwserver.tcp.status_line import parse_status
from nfwserver.tracking.catalog import Catalog
from nfwserver.tracking.elements import load_element_file
from tests.autotrack.test_runtime import PRIORITY, START, _Expected, _passes_csv
from tests.autotrack.test_schedule_cli import AMATEUR, SIX, _oracle

LIST = "[" + ", ".join(f'"{name}"' for name in SIX) + "]"
CONFIG = f'[observer]\nlocation = "JO02ae"\n[autotrack]\nenabled = true\nsatellites = {LIST}\n'


def _expected(capsys: pytest.CaptureFixture[str]) -> _Expected:
    """The schedule's satellite at any instant of the day after START, by the oracle (reads ``passes``' CSV)."""
    rows = _passes_csv(capsys, AMATEUR, START, 26)
    return _Expected(rows, _oracle(rows, PRIORITY, 60.0))


def _names(catalog: Catalog) -> dict[int, str]:
    return {s.catalog_number: s.dde_name for s in catalog}


def test_sat_switches_autotrack_off_and_auto_on_resumes_for_tcp_and_dde_clients(capsys) -> None:
    expected = _expected(capsys)
    catalog = Catalog(load_element_file(AMATEUR).sets)
    config = parse_config(CONFIG)
    clock = VirtualClock(START)
    core = StationCore(catalog, config.observer, clock, rate_hz=1.0)
    autotrack = StationAutotrack(core, clock, lambda: config)
    autotrack.restore(None, None, None, "no state file")
    system = FakeDdeSystem(received_capacity=40_000)  # every string of the run is kept
    NovaDdeService(core).attach(system.server_transport())
    dde = system.connect("NFW32", "NFW_DATA")
    dde.poke("NFW_SERVER", "TUNE ON")
    dde.start_advise("NFW_SERVER")
    tcp = NovaTcpProtocol(core, extra=autotrack.status_fields)
    names = _names(catalog)

    def run(seconds: float) -> list[tuple[datetime, str]]:
        seen: list[tuple[datetime, str]] = []
        start = len(dde.texts())

        def before(_: float) -> None:
            autotrack.follow(clock.now())
            seen.append((clock.now(), ""))

        run_virtual(core, clock, seconds, before_tick=before)
        texts = dde.texts()[start:]
        return [(when, text.split()[0]) for (when, _), text in zip(seen, texts, strict=True)]

    first = run(3600.0)
    assert [name for when, name in first] == [names[expected(when)] for when, _ in first]  # type: ignore[index]
    status = parse_status(tcp.status_line())
    assert status["auto"] == "on" and status["auto_next"] != "none" and "auto_off" not in status

    # a TCP client chooses a satellite the schedule does not name now: it wins, and is told autotrack is off
    wanted = next(n for n in PRIORITY if n != expected(clock.now()))
    reply = tcp.handle(f"SAT={wanted}", "tcp 127.0.0.1:1")
    assert reply is not None and reply.lines == (
        f"OK warning: autotrack switched off: SAT={wanted} from tcp 127.0.0.1:1 chose the satellite; AUTO ON "
        "resumes it",)
    notes = [e.text for e in core.events.recent(20) if e.kind == "note"]
    assert any(text.startswith(f"autotrack off: SAT={wanted} from tcp 127.0.0.1:1") for text in notes)
    manual = run(4 * 3600.0)  # long enough for the schedule to change its satellite
    assert {expected(when) for when, _ in manual} - {wanted}
    assert {name for _, name in manual} == {names[wanted]}
    status = parse_status(tcp.status_line())
    assert status["auto"] == "off" and status["auto_off"].startswith(f"SAT={wanted} from tcp 127.0.0.1:1")

    # a DDE client switches it on again: the next tick names the schedule's satellite
    dde.poke("NFW_SERVER", "AUTO ON")
    resumed = run(3600.0)
    assert [name for _, name in resumed] == [names[expected(when)] for when, _ in resumed]  # type: ignore[index]
    assert parse_status(tcp.status_line())["auto"] == "on"
    # a SAT= while autotrack is off says nothing of it
    tcp.handle("AUTO OFF", "tcp 127.0.0.1:1")
    assert tcp.handle(f"SAT={wanted}", "tcp 127.0.0.1:1").lines == ("OK",)  # type: ignore[union-attr]


def test_a_station_without_autotrack_refuses_auto_with_the_reason() -> None:
    core = StationCore(Catalog(load_element_file(AMATEUR).sets), parse_config(CONFIG).observer, VirtualClock(START))
    reply = NovaTcpProtocol(core).handle("AUTO ON", "tcp 127.0.0.1:1")
    assert reply is not None and reply.lines[0].startswith("ERROR this station has no autotrack")


def _station(tmp_path: Path, enabled: bool) -> Station:
    path = tmp_path / "station.toml"
    path.write_text(CONFIG.replace("enabled = true", f"enabled = {'true' if enabled else 'false'}")
                    + f'[server]\nstate_file = "{tmp_path / "state.json"}"\n[tcp]\nenabled = true\nport = 0\n')
    station = Station(load_config(str(path)), VirtualClock(START), transport=FakeDdeSystem().server_transport())
    station.start()
    return station


def _ask(station: Station, line: str) -> str:
    from tests.tcp.conftest import LineClient

    assert station.tcp is not None
    client = LineClient(station.tcp.address)
    try:
        client.read_line()
        return client.ask(line)
    finally:
        client.close()


@pytest.mark.parametrize(("enabled", "command"), [(False, "AUTO ON"), (True, "AUTO OFF")])
def test_the_mode_survives_a_restart(tmp_path, enabled: bool, command: str) -> None:
    station = _station(tmp_path, enabled)
    try:
        assert station.autotrack.runtime.on is enabled
        assert _ask(station, command) == "OK"
    finally:
        station.stop()
    saved = json.loads((tmp_path / "state.json").read_text())
    assert (saved["autotrack"], saved["autotrack_enabled"]) == (not enabled, enabled)
    again = _station(tmp_path, enabled)
    try:
        assert again.autotrack.runtime.on is (not enabled)
        status = parse_status(_ask(again, "STATUS"))
        assert status["auto"] == ("off" if enabled else "on")
        if enabled:
            assert status["auto_off"].startswith("AUTO OFF from tcp 127.0.0.1:") and "before the restart" in \
                status["auto_off"]
    finally:
        again.stop()


def test_an_edit_of_enabled_since_wins_over_the_saved_mode(tmp_path) -> None:
    _station(tmp_path, False).stop()  # off, as configured
    assert json.loads((tmp_path / "state.json").read_text())["autotrack"] is False
    edited = _station(tmp_path, True)
    try:
        assert edited.autotrack.runtime.on
    finally:
        edited.stop()


def test_a_simulated_day_names_the_scheduled_satellite_every_second(tmp_path, capsys) -> None:
    expected = _expected(capsys)
    config = tmp_path / "station.toml"
    config.write_text(CONFIG)
    start = START.strftime("%Y-%m-%dT%H:%M:%SZ")
    assert main(["simulate", "--config", str(config), "--elements", str(AMATEUR), "--start", start,
                 "--duration", "86400", "--rate", "1"]) == 0
    out, err = capsys.readouterr()
    assert "autotrack on from [autotrack] enabled" in err
    names = _names(Catalog(load_element_file(AMATEUR).sets))
    lines = out.splitlines()
    assert len(lines) == 86401
    wrong = []
    for line in lines:
        stamp, text = line.split("\t")
        when = datetime.strptime(stamp, "%Y-%m-%dT%H:%M:%S.%fZ").replace(tzinfo=timezone.utc)
        if text.split()[0] != names[expected(when)]:  # type: ignore[index]
            wrong.append(line)
    assert wrong == []
    assert START + timedelta(hours=24) == when


def test_simulate_takes_auto_pokes(tmp_path, capsys) -> None:
    expected = _expected(capsys)
    config = tmp_path / "station.toml"
    config.write_text(CONFIG.replace("enabled = true", "enabled = false"))
    start = START.strftime("%Y-%m-%dT%H:%M:%SZ")
    manual = next(n for n in PRIORITY if n != expected(START))
    assert main(["simulate", "--config", str(config), "--elements", str(AMATEUR), "--start", start, "--sat",
                 str(manual), "--duration", "20", "--rate", "1", "--poke", "10:AUTO ON"]) == 0
    out, err = capsys.readouterr()
    assert "t+10 s  poke 'AUTO ON': accepted" in err
    catalog_names = _names(Catalog(load_element_file(AMATEUR).sets))
    names = [line.split("\t")[1].split()[0] for line in out.splitlines()]
    assert names[:10] == [catalog_names[manual]] * 10
    assert names[10:] == [catalog_names[expected(START + timedelta(seconds=k))] for k in range(10, 21)]  # type: ignore[index]


def test_watch_shows_autotrack_and_why_it_is_off() -> None:
    from nfwserver.cli.watch_view import WatchUpdate, block_lines, plain_line
    from nfwserver.tcp.status_line import format_status

    line = format_status({"satellite": 25544, "name": "ISS", "auto": False, "auto_next": "SO-50 04:09-04:23",
                          "auto_off": "AUTO OFF from tcp 127.0.0.1:5"})
    update = WatchUpdate(START, "127.0.0.1 port 8090", True, parse_status(line))
    assert "Autotrack  OFF  (AUTO OFF from tcp 127.0.0.1:5)  next pass SO-50 04:09-04:23" in block_lines(update)
    assert " auto=off " in plain_line(update) + " "
    assert update.to_json()["auto"] is False


def test_the_dashboard_gets_the_running_stations_schedule_and_its_auto_command() -> None:
    from tests.waiting import wait_for
    from tests.web.conftest import TOKEN, config_text, start_station

    web = start_station(config_text() + "[autotrack]\nenabled = true\n")
    try:
        def scheduled() -> bool:
            web.advance(0.2)
            return web.get("/api/passes").get("schedule") is not None

        wait_for(scheduled, 20.0, "the schedule on /api/passes")
        wait_for(lambda: web.station.core.selected_by == "autotrack", 10.0, "autotrack's selection")
        status, body = web.post({"command": "AUTO OFF", "token": TOKEN})
        assert (status, body["ok"]) == (200, True) and not web.station.autotrack.runtime.on
    finally:
        web.station.stop()


def test_the_reason_autotrack_is_off_does_not_grow_with_each_restart(tmp_path) -> None:
    """Each restart appended "(before the restart, kept in FILE)" to the reason it read back and saved it again:
    after a few restarts the reason outgrew what the state file takes back, and the saved state was lost."""
    station = _station(tmp_path, True)
    try:
        assert _ask(station, "AUTO OFF") == "OK"
    finally:
        station.stop()
    reasons = []
    for _ in range(4):
        again = _station(tmp_path, True)
        again.stop()
        reasons.append(json.loads((tmp_path / "state.json").read_text())["autotrack_off"])
    assert reasons[0].startswith("AUTO OFF from tcp 127.0.0.1:") and reasons.count(reasons[0]) == 4, reasons
    assert reasons[0].count("before the restart") <= 1


def test_a_command_right_after_config_set_sees_the_change(tmp_path) -> None:
    """``config set autotrack.satellites ...`` then ``poke "AUTO ON"`` (README's journey): the station's clock
    stands still here, so its watcher never looks; the command itself must see the file as it is now."""
    path = tmp_path / "station.toml"
    path.write_text(CONFIG.replace(f"satellites = {LIST}\n", "").replace("enabled = true", "enabled = false")
                    + f'[server]\nstate_file = "{tmp_path / "state.json"}"\n[tcp]\nenabled = true\nport = 0\n')
    station = Station(load_config(str(path)), VirtualClock(START), transport=FakeDdeSystem().server_transport())
    station.start()
    try:
        station.watch_config(str(path))
        assert main(["config", "set", "autotrack.satellites", '["ISS", "AO-7"]', "--config", str(path)]) == 0
        assert _ask(station, "AUTO ON") == "OK"  # not "OK warning: ... nothing to work"
        assert main(["config", "set", "autotrack.satellites", '["NO-SUCH-SAT"]', "--config", str(path)]) == 0
        assert "NO-SUCH-SAT is not in the catalog" in _ask(station, "AUTO ON")
    finally:
        station.stop()
