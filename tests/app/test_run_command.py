"""``nfwserver run``: headless reporting on the station clock, and a console failure that never stops the station."""

from __future__ import annotations

import threading
from pathlib import Path

from nfwserver.cli.run_command import RunPlan, serve
from nfwserver.clock import VirtualClock
from nfwserver.config.loader import load_config, observer_hint
from nfwserver.console.app import NfwConsole
from nfwserver.dde.clipboard import CF_TEXT
from nfwserver.fake_dde import FakeDdeSystem
from tests.app.headless_run import serve_once
from tests.conftest import advance_until
from tests.dde.conftest import ISS_PASS
from tests.waiting import wait_for

CONFIG = '[observer]\nlocation = "JO02ae"\n[server]\nsatellite = 25544\nstate_file = "none"\n'


def _config(tmp_path: Path, text: str = CONFIG):
    path = tmp_path / "station.toml"
    path.write_text(text)
    return load_config(str(path))



def test_headless_prints_the_log_file_logs_the_start_and_a_status_every_ten_minutes(tmp_path, capsys) -> None:
    config = _config(tmp_path)
    log_file = tmp_path / "logs" / "nfw.log"
    clock = VirtualClock(ISS_PASS.aos)
    stop = threading.Event()
    plan = RunPlan(console=False, log_file=log_file, clock=clock, transport=FakeDdeSystem().server_transport(),
                   stop=stop)

    def statuses() -> int:
        return log_file.read_text().count(" status: ") if log_file.exists() else 0

    def drive() -> None:
        try:
            wait_for(lambda: "outputs:" in (log_file.read_text() if log_file.exists() else ""), 20.0,
                     "the start line in the log")
            advance_until(clock, lambda: statuses() >= 2, step_s=30.0, limit_s=1500.0)
        finally:
            stop.set()  # whatever happened, the run must end (a failed wait shows in the asserts below)

    driver = threading.Thread(target=drive)
    driver.start()
    assert serve(config, plan) == 0
    driver.join()
    err = capsys.readouterr().err
    assert err.splitlines()[0] == f"nfwserver: logging to {log_file}"
    text = log_file.read_text()
    assert "observer 52.18750N 0.04167E 0 m (configured)" in text  # JO02ae's centre
    assert "satellite ISS (25544)" in text
    assert "outputs: Nova DDE (services NFW32, NFW_SERVER; topic NFW_DATA; items NFW_SERVER, NFW_DATA)" in text
    # Exactly two status lines after 20-25 minutes of station time, none earlier than ten minutes in.
    elapsed = (clock.now() - ISS_PASS.aos).total_seconds()
    assert 1200 <= elapsed < 1500 + 30 and statuses() == 2
    assert "status: ISS (25544) AZ" in text and "DDE clients 0 (0 advise)" in text


def test_the_no_observer_hint_names_the_file_in_use(tmp_path, capsys) -> None:
    config = _config(tmp_path, '[server]\nstate_file = "none"\n')
    assert serve_once(config, tmp_path) == 0
    err = capsys.readouterr().err
    assert f"nfwserver: {observer_hint(config)}" in err and str(tmp_path / "station.toml") in err


class ExplodingConsole(NfwConsole):
    """A console that fails as soon as it is on screen."""

    def on_mount(self) -> None:
        super().on_mount()
        raise RuntimeError("the console broke")


def test_a_console_failure_is_reported_in_one_sentence_and_the_station_keeps_serving(tmp_path, capsys) -> None:
    config = _config(tmp_path)
    log_file = tmp_path / "nfw.log"
    clock = VirtualClock(ISS_PASS.aos)
    system = FakeDdeSystem()
    stop = threading.Event()
    made: list[ExplodingConsole] = []

    def make_console(station, config, hint):
        made.append(ExplodingConsole(station.core, station.transport_note, hint))
        return made[-1]

    plan = RunPlan(console=True, log_file=log_file, clock=clock, transport=system.server_transport(),
                   make_console=make_console, console_options={"headless": True, "size": (80, 24)}, stop=stop)
    received: list[str] = []

    def drive() -> None:
        # Once the console has failed and the run carries on headless, a DDE client still gets the feed.
        try:
            wait_for(lambda: log_file.exists() and "outputs:" in log_file.read_text(), 20.0,
                     "the start line in the log")
            client = system.connect("NFW32", "NFW_DATA")
            client.on_receive = lambda r: received.append(r.text) if r.kind == "data" else None
            client.start_advise("NFW_SERVER", CF_TEXT, hot=True)
            client.poke("NFW_SERVER", "TUNE ON")
            advance_until(clock, lambda: len(received) >= 5, real_timeout_s=60.0)
        finally:
            stop.set()  # whatever happened, the run must end (a failed wait shows in the asserts below)

    driver = threading.Thread(target=drive)
    driver.start()
    assert serve(config, plan) == 0
    driver.join()
    assert made and isinstance(made[0].failure, RuntimeError)
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"nfwserver: the console failed (RuntimeError: the console broke); the station keeps serving "
                   f"without it, logging to {log_file}; stop it with Ctrl+C."]
    assert len(received) >= 5 and all(text.startswith("ISS AZ:") for text in received)
    log_text = log_file.read_text()
    assert "the console stopped: RuntimeError: the console broke" in log_text and "Traceback" in log_text


def test_the_start_up_line_names_where_the_rotor_daemon_is(tmp_path) -> None:
    """#34 item 10: the radio was named with its rigctld address, the rotor only as ``rotor (rotctld)``."""
    from nfwserver.app.station import Station
    from nfwserver.cli.station_runner import enabled_outputs
    from nfwserver.clock import VirtualClock
    from nfwserver.config.loader import parse_config

    config = parse_config('[rotor]\nbackend = "rotctld"\nhost = "127.0.0.1"\nport = 14533\n'
                          '[radio]\nbackend = "rigctld"\nport = 14532\n[server]\nstate_file = "none"\n')
    station = Station(config, VirtualClock(ISS_PASS.aos), transport=FakeDdeSystem().server_transport())
    outputs = enabled_outputs(station)  # construction only: nothing is connected
    assert "rotor (rotctld 127.0.0.1:14533)" in outputs and "radio (rigctld 127.0.0.1:14532)" in outputs
