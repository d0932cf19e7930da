"""``nfwserver watch``: a real station with TCP on a free loopback port, watched as a script would (``--json``)
and through a stop and restart of the station; ``nfwserver poke WATCH`` points at it."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import threading
from datetime import datetime, timedelta, timezone
from pathlib import Path

import pytest

from nfwserver.app.station import Station
from nfwserver.cli import main
from nfwserver.cli.watch_command import StationWatcher
from nfwserver.cli.watch_view import WatchUpdate, block_lines, plain_line
from nfwserver.clock import VirtualClock
from nfwserver.config.loader import load_config
from nfwserver.fake_dde import FakeDdeSystem
from tests.conftest import DATA, ROOT
from tests.dde.conftest import ISS_PASS
from tests.hamlib_daemons import free_port
from tests.waiting import wait_for


def _config(tmp_path: Path, tcp_port: int) -> Path:
    path = tmp_path / "config.toml"
    path.write_text(
        '[observer]\nlocation = "52.2053,0.1218,20"\n'
        f'[elements]\nfiles = ["{DATA / "visual.txt"}"]\nuse_bundled = false\n'
        '[server]\nsatellite = 25544\ntune = true\ntrack = true\nstate_file = "none"\n'
        '[rotor]\nbackend = "sim"\n'
        f'[tcp]\nenabled = true\nport = {tcp_port}\n')
    return path


def _station(path: Path, clock: VirtualClock) -> Station:
    station = Station(load_config(str(path)), clock, transport=FakeDdeSystem().server_transport())
    station.start()
    wait_for(lambda: station.core.current_text() or clock.advance(0.2), 10.0, "the first tick on the virtual clock")
    return station


def _nova_values(text: str) -> dict[str, str]:
    name, *pairs = text.split(" ")
    return {"name": name, **{k.lower(): v for k, v in (p.split(":", 1) for p in pairs)}}


def test_watch_json_reads_n_updates_that_match_the_published_string(tmp_path, capsys) -> None:
    path = _config(tmp_path, free_port())
    clock = VirtualClock(ISS_PASS.aos + timedelta(seconds=300))  # ISS well up
    station = _station(path, clock)
    try:
        published = station.core.current_text()
        assert main(["watch", "--config", str(path), "--json", "--count", "3", "--interval", "0.05"]) == 0
    finally:
        station.stop()
    out = capsys.readouterr().out.splitlines()
    assert len(out) == 3
    for line in out:
        update = json.loads(line)
        nova = _nova_values(update["nova"])
        assert update["connected"] is True and update["nova"] == published
        assert (update["name"], update["satellite"], update["satellite_from"]) == (nova["name"], 25544, "config")
        assert update["status"]["az"] == nova["az"] and update["status"]["el"] == nova["el"]
        assert update["status"]["rr"] == nova["rr"] and nova["ah"] == "Y" and update["ah"] is True
        assert abs(update["az"] - float(nova["az"])) < 1e-9 and abs(update["rr"] - float(nova["rr"])) < 1e-12
        assert update["tune"] is True and update["track"] is True and update["faults"] == []
        assert update["rotor"] in ("ok", "retrying", "unreachable")  # sim rotor, polled or not yet
        assert update["elements_stale"] is False and 0 <= update["elements_age_d"] < 14  # a pass of the set's day
        assert update["status_word"] == update["status"]["status"] and isinstance(update["status_bits"], list)


def test_watch_reconnects_when_the_station_stops_and_returns(tmp_path) -> None:
    port = free_port()
    path = _config(tmp_path, port)
    clock = VirtualClock(ISS_PASS.aos)
    watch_clock = VirtualClock(datetime(2026, 5, 8, tzinfo=timezone.utc))  # the watcher's waits, stepped here
    updates: list[WatchUpdate] = []
    stop = threading.Event()
    watcher = StationWatcher("127.0.0.1", port, updates.append, clock=watch_clock, interval_s=1.0, timeout_s=5.0,
                             stop=stop)
    thread = threading.Thread(target=watcher.run, daemon=True)

    def step_until(predicate) -> None:
        wait_for(lambda: predicate() or watch_clock.advance(0.5), 20.0,
                 lambda: f"the watcher's updates; the last: {[plain_line(u) for u in updates[-3:]]}")

    thread.start()
    try:
        step_until(lambda: len(updates) >= 2)  # nothing listens yet: "not reachable yet", retrying
        assert not any(u.connected for u in updates)
        assert not updates[0].ever_connected and "not reachable yet" in plain_line(updates[0])
        assert [u.retry_s for u in updates[:2]] == [1.0, 2.0]
        station = _station(path, clock)
        try:
            step_until(lambda: sum(u.connected for u in updates) >= 2)
            assert updates[-1].fields["satellite"] == "25544" and updates[-1].nova == station.core.current_text()
        finally:
            station.stop()
        step_until(lambda: not updates[-1].connected)
        lost = updates[-1]
        assert lost.ever_connected and lost.retry_s == 1.0  # back to the short wait after a good connection
        assert f"station lost: the station at 127.0.0.1 port {port} closed the connection (stopped or restarting?)" \
            in plain_line(lost)
        assert "station lost" in "\n".join(block_lines(lost))
        seen = len(updates)
        station = _station(path, clock)
        try:
            step_until(lambda: len(updates) > seen and updates[-1].connected)
            assert updates[-1].nova == station.core.current_text()
        finally:
            station.stop()
    finally:
        stop.set()
        watch_clock.advance(10)
        thread.join(5)
    assert not thread.is_alive()


def test_the_block_shows_devices_faults_and_who_chose_the_satellite() -> None:
    fields = {"satellite": "25544", "name": "ISS", "satellite_from": "tcp_127.0.0.1:5000", "tune": "on",
              "track": "off", "radio_tuning": "off", "status": "0x0028", "interface": "1", "az": "92.7",
              "el": "21.7", "rr": "6.4060915074", "ah": "Y", "faults": "rotor", "rotor_fault": "rotctld_lost",
              "rotor": "retrying", "rotor_az": "90.0", "rotor_el": "20.0", "radio": "ok", "radio_rx": "437800000",
              "easycomm": "open", "elements_age_d": "3.2", "elements_stale": "no"}
    update = WatchUpdate(datetime(2026, 5, 8, 12, tzinfo=timezone.utc), "127.0.0.1 port 8090", True, fields,
                         "ISS AZ:92.7 EL:21.7 RR:6.4060915074 AH:Y")
    text = "\n".join(block_lines(update))
    for expected in ("ISS (25544), chosen by tcp_127.0.0.1:5000", "Nova       ISS AZ:92.7 EL:21.7 RR:6.4060915074 AH:Y",
                     "AZ 92.7  EL 21.7", "TUNE ON  TRACK OFF", "0x0028: tuning disabled, not in view",
                     "rotor: rotctld lost", "Rotor      retrying  at 90.0/20.0", "rx 437800000 Hz", "EasyComm   open",
                     "3.2 days old"):
        assert expected in text, expected
    assert max(len(line) for line in block_lines(update)) <= 76


def test_poke_watch_points_at_nfwserver_watch(capsys) -> None:
    assert main(["poke", "--port", "9", "WATCH"]) == 2
    assert "`nfwserver watch`" in capsys.readouterr().err


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_watch_stops_cleanly_on_ctrl_c_and_sigterm(tmp_path, sig) -> None:
    """A real SIGINT (Ctrl+C) or SIGTERM while the view waits for a station: exit code 0, no traceback."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    closed = socket.socket()  # bound, never listening: its port refuses connections and no other test can take it
    closed.bind(("127.0.0.1", 0))
    port = closed.getsockname()[1]
    # started with SIGINT ignored, as a background job of a script would be: the view must still stop on it
    proc = subprocess.Popen([sys.executable, "-m", "nfwserver", "watch", "--port", str(port), "--json"],
                            cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN))
    try:
        first = json.loads(proc.stdout.readline())  # the first attempt failed: it is waiting to retry
        assert first["connected"] is False and first["ever_connected"] is False and first["retry_s"] == 1.0
        proc.send_signal(sig)
        assert proc.wait(10) == 0
        assert "Traceback" not in proc.stderr.read()
    finally:
        closed.close()
        if proc.poll() is None:
            proc.kill()
            proc.wait()
