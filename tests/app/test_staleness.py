"""Staleness where the user looks (#25 item 2): STATUS fields and `nfwserver status`, the console's pass list.
(`passes`: tests/tracking/test_station_defaults_cli.py.)  The TCP SUMMARY line stays Nova's string."""

from __future__ import annotations

from datetime import timedelta

from nfwserver.app.station import Station
from nfwserver.cli import main
from nfwserver.clock import VirtualClock
from nfwserver.config.loader import load_config
from nfwserver.console.pass_view import PassSearch, pass_table
from nfwserver.console.time_display import TimeDisplay
from nfwserver.fake_dde import FakeDdeSystem
from nfwserver.tcp.status_line import parse_status
from nfwserver.tracking.catalog import Catalog
from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.passes import find_passes
from tests.conftest import DATA
from tests.hamlib_daemons import free_port

HOME = Observer(52.2, 0.12, 20.0)
ISS = next(s for s in load_element_file(DATA / "visual.txt").sets if s.catalog_number == 25544)


def _fields(line: str) -> dict[str, str]:
    return parse_status(line)


def test_status_says_how_old_the_selected_satellites_elements_are(tmp_path, capsys) -> None:
    port = free_port()
    config = tmp_path / "c.toml"
    config.write_text(f'[elements]\nfiles = ["{DATA / "visual.txt"}"]\nuse_bundled = false\nstore = "none"\n'
                      f'stale_days = 10\n[tcp]\nenabled = true\nport = {port}\n[server]\nstate_file = "none"\n')
    clock = VirtualClock(ISS.epoch + timedelta(days=3))
    station = Station(load_config(str(config)), clock, transport=FakeDdeSystem().server_transport())
    station.start()
    try:
        assert main(["status", "--config", str(config)]) == 0
        out, err = capsys.readouterr()
        assert _fields(out)["elements_age_d"] == "3.0" and _fields(out)["elements_stale"] == "no" and err == ""
        clock.advance(8 * 86400.0)
        assert main(["status", "--config", str(config)]) == 0
        out, err = capsys.readouterr()
        assert _fields(out)["elements_age_d"] == "11.0" and _fields(out)["elements_stale"] == "yes"
        assert err == ("nfwserver: the elements of ISS are 11.0 days old, older than [elements] stale_days: "
                       "positions drift; `nfwserver elements update` fetches current ones\n")
        assert main(["poke", "--config", str(config), "TUNE ON"]) == 0
        station.core.tick()
        capsys.readouterr()
        assert main(["poke", "--config", str(config), "SUMMARY"]) == 0
        assert capsys.readouterr().out.startswith("ISS AZ:")  # Nova's string, unchanged
    finally:
        station.stop()


def test_the_console_pass_list_flags_old_elements() -> None:
    catalog = Catalog([ISS])
    times = TimeDisplay()
    for age, flagged in ((3.0, False), (20.0, True)):
        now = ISS.epoch + timedelta(days=age)
        passes = find_passes([catalog.get(25544)], HOME, now, now + timedelta(hours=12))
        text = pass_table(PassSearch(now, 25544, passes), catalog, times, now).plain
        assert text.splitlines()[1].startswith("ISS ")
        assert ("!" in text.splitlines()[1]) is flagged
        assert ("! elements up to 20 days old (over 14): positions drift; run `nfwserver elements update`"
                in text) is flagged
    now = ISS.epoch + timedelta(days=20)
    passes = find_passes([catalog.get(25544)], HOME, now, now + timedelta(hours=12))
    assert "!" not in pass_table(PassSearch(now, 25544, passes), catalog, times, now, stale_days=30).plain
