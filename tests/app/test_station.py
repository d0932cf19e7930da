"""The assembled station: defaults, element sources over local HTTP, headless run."""

from __future__ import annotations

from datetime import datetime, timezone

import pytest

from nfwserver.app.element_sources import bundled_elements, fetch_all
from nfwserver.app.station import Station
from nfwserver.cli import main
from nfwserver.clock import SystemClock, VirtualClock
from nfwserver.config.loader import parse_config
from nfwserver.config.schema import Config
from nfwserver.fake_dde import FakeDdeSystem
from tests.conftest import DATA
from tests.waiting import wait_for


def test_bundled_elements_hold_the_popular_satellites() -> None:
    result = bundled_elements()
    numbers = {s.catalog_number for s in result.sets}
    assert {25544, 27607, 7530, 24278}.issubset(numbers) and not result.rejected


def test_elements_from_local_http_and_a_dead_url(http_server) -> None:
    result = fetch_all(urls=(f"{http_server}/visual.txt", f"{http_server}/missing.txt", "http://127.0.0.1:9/x"),
                       use_bundled=False, timeout_s=5)
    assert len(result.sets) == 148
    assert len(result.failed) == 2


def test_station_serves_dde_on_defaults() -> None:
    system = FakeDdeSystem()
    station = Station(Config(), SystemClock(), transport=system.server_transport())
    assert len(station.catalog) == 0  # construction does no I/O
    station.start()
    assert len(station.catalog) >= 40
    try:
        conv = system.connect("NFW32", "NFW_DATA")
        conv.poke("NFW_SERVER", "TUNE ON")
        station.core.tick()
        assert conv.request_text("NFW_SERVER").startswith("ISS AZ:")
    finally:
        station.stop()
    assert not conv.connected


def test_refresh_takes_newer_elements_only(tmp_path) -> None:
    keps = tmp_path / "keps.txt"
    keps.write_text((DATA / "visual.txt").read_text())
    config = parse_config(f'[elements]\nfiles = ["{keps}"]\nuse_bundled = false\n')
    station = Station(config, VirtualClock(datetime(2026, 5, 8, tzinfo=timezone.utc)),
                      transport=FakeDdeSystem().server_transport())
    station.start()
    try:
        assert len(station.catalog) == 148
        summary = station.refresh_elements()
    finally:
        station.stop()
    assert summary.added == [] and summary.updated == [] and len(summary.not_newer) == 148


def test_run_headless_for_a_bounded_time(tmp_path, capsys) -> None:
    log_file = tmp_path / "nfw.log"
    config = tmp_path / "c.toml"
    config.write_text('[observer]\nlocation = "JO02ae"\n[server]\nrate_hz = 20\n')
    assert main(["run", "--headless", "--duration", "0.3", "--config", str(config), "--log-file", str(log_file)]) == 0
    err = capsys.readouterr().err
    assert "in-process fake DDE transport" in err and "satellites loaded" in err
    assert "stopped" in log_file.read_text()


def test_run_refuses_a_bad_config(tmp_path, capsys) -> None:
    config = tmp_path / "c.toml"
    config.write_text("[server]\nrate_hz = 500\n")
    assert main(["run", "--headless", "--duration", "0.1", "--config", str(config)]) == 1
    assert "[server] rate_hz" in capsys.readouterr().err


@pytest.mark.hamlib
def test_station_tunes_a_real_rigctld_when_configured(rigctld, tmp_path) -> None:

    config = parse_config(
        f'[radio]\nbackend = "rigctld"\nport = {rigctld.port}\nenabled = true\n'
        "[[satellites.channels]]\ncatalog_number = 25544\nname = \"ISS beacon\"\ndownlink_hz = 145800000\n"
    )
    assert config.channels[25544].uplink_hz is None and 27607 in config.channels
    station = Station(config, SystemClock(), transport=FakeDdeSystem().server_transport())
    station.start()
    try:
        # the publisher ticks at 5 Hz and the radio worker follows
        wait_for(lambda: station.radio.last_result is not None, 10.0, "the radio's first Doppler tuning")
    finally:
        station.stop()
    result = station.radio.last_result
    assert result is not None and abs(result.rx_hz - 145_800_000) < 145_800_000 * 8 / 299792.458
    assert int(rigctld.query("f")[0]) == result.rx_hz


def test_station_with_a_simulated_rotor_reports_the_antenna_position() -> None:
    from nfwserver.clock import VirtualClock
    from nfwserver.core.publisher import run_virtual
    from tests.dde.conftest import ISS_PASS

    config = parse_config('[observer]\nlocation = "52.2053,0.1218,20"\n[rotor]\nbackend = "sim"\n'
                          'geometry = "overlap-450"\nafter_los = "stay"\n')
    clock = VirtualClock(ISS_PASS.tca)
    station = Station(config, clock, transport=FakeDdeSystem().server_transport())
    station._load_catalog()  # what start() loads, without starting the threads: ticks run synchronously here
    station.core.select_satellite(25544)
    station.core.command("TRACK ON")
    station.core.subscribe(station.rotor.process)
    run_virtual(station.core, clock, 60)
    antenna = station.core.snapshot().state.antenna
    la = station.core.snapshot().last_sample.look_angles
    assert antenna.source == "rotor"
    assert abs(((antenna.azimuth_deg - la.azimuth_deg) + 180) % 360 - 180) < 15
    assert station.rotor.plan is not None


def test_rotor_config_errors_name_the_key() -> None:
    from nfwserver.config.loader import ConfigError

    with pytest.raises(ConfigError) as info:
        parse_config('[rotor]\nbackend = "serial"\ngeometry = "round"\nthreshold_deg = 90\nafter_los = "sleep"\n')
    text = str(info.value)
    for key in ("[rotor] backend", "[rotor] geometry", "[rotor] threshold_deg", "[rotor] after_los"):
        assert key in text
