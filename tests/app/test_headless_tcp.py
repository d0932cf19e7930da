"""A headless station reached from outside: start-up TUNE/TRACK, a real rotctld following a pass, and
``nfwserver status`` / ``nfwserver poke`` over the station's TCP port."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from datetime import timedelta
from pathlib import Path

import pytest

from nfwserver.app.station import Station
from nfwserver.cli import main
from nfwserver.clock import VirtualClock
from nfwserver.config.loader import load_config
from nfwserver.fake_dde import FakeDdeSystem
from nfwserver.rotor.coupling import angular_distance
from nfwserver.tcp.status_line import parse_status
from tests.conftest import DATA, ROOT
from tests.dde.conftest import ISS_PASS
from tests.hamlib_daemons import HamlibDaemon, free_port
from tests.waiting import wait_for


def _config(tmp_path: Path, tcp_port: int, rotor_port: int | None = None) -> Path:
    rotor = (f'[rotor]\nbackend = "rotctld"\nhost = "127.0.0.1"\nport = {rotor_port}\nflip = "off"\n'
             if rotor_port else "")
    path = tmp_path / "config.toml"
    path.write_text(
        '[observer]\nlocation = "52.2053,0.1218,20"\n'
        f'[elements]\nfiles = ["{DATA / "visual.txt"}"]\nuse_bundled = false\n'
        '[server]\nsatellite = 25544\ntune = true\ntrack = true\nstate_file = "none"\n'
        f'{rotor}[tcp]\nenabled = true\nport = {tcp_port}\n')
    return path


def _fields(line: str) -> dict[str, str]:
    return parse_status(line)


@pytest.mark.hamlib
def test_a_headless_station_follows_a_pass_with_rotctld_and_answers_status_and_poke(tmp_path, capsys) -> None:
    with HamlibDaemon("rotctld") as rotctld:
        path = _config(tmp_path, free_port(), rotctld.port)
        start = ISS_PASS.aos + timedelta(seconds=450)  # ISS setting in the east, about 22 degrees up
        clock = VirtualClock(start)
        station = Station(load_config(str(path)), clock, transport=FakeDdeSystem().server_transport())
        station.start()  # the dummy rotor starts at 0/0, about 95 degrees away
        try:
            assert station.core.state.snapshot().tracking and station.core.state.snapshot().feed_on

            def distance() -> float:
                az, el = (float(v) for v in rotctld.query("p", 2))
                la = station.core.tracker.last_sample.look_angles
                return angular_distance(az, el, la.azimuth_deg, la.elevation_deg)

            distances: list[float] = []

            def pointed() -> bool:  # the dummy rotor turns in real time: keep the clock with it
                for _ in range(5):
                    clock.advance(0.1)
                    time.sleep(0.1)
                distances.append(distance())
                return distances[-1] < 4.0

            wait_for(pointed, 40.0, lambda: f"the rotor to point at the satellite (off by {distances[-1]:.1f} deg)")
            assert distances[0] > 60.0, distances

            assert main(["status", "--config", str(path)]) == 0
            fields = _fields(capsys.readouterr().out.strip())
            assert [fields[k] for k in ("satellite", "tune", "track", "rotor")] == ["25544", "on", "on", "ok"]
            assert abs(float(fields["rotor_az"]) - station.core.tracker.last_sample.look_angles.azimuth_deg) < 5.0
            assert main(["poke", "--config", str(path), "TRACK OFF"]) == 0
            assert capsys.readouterr().out == "OK\n"
            assert not station.core.state.snapshot().tracking
            assert main(["poke", "--config", str(path), "SAT=1"]) == 1
            assert "satellite 1 is not in the catalog" in capsys.readouterr().err
            events = [e for e in station.core.events.recent() if e.kind == "poke" and e.client.startswith("tcp ")]
            assert [e.text for e in events] == ["TRACK OFF", "SAT=1"]
        finally:
            station.stop()
    assert main(["status", "--config", str(path)]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no station answers on 127.0.0.1 port" in err


def test_nfwserver_run_headless_serves_tcp_with_start_up_tune_and_track(tmp_path, capsys) -> None:
    port = free_port()
    path = _config(tmp_path, port)
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen([sys.executable, "-m", "nfwserver", "run", "--headless", "--duration", "60",
                             "--config", str(path), "--log-file", str(tmp_path / "log.txt")],
                            cwd=ROOT, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        def answers() -> bool:
            assert proc.poll() is None, proc.stderr.read().decode()  # a station that exited fails at once
            return main(["status", "--config", str(path), "--timeout", "1"]) == 0

        wait_for(answers, 30.0, "nfwserver status to reach the station", interval_s=0.2)
        fields = _fields(capsys.readouterr().out.strip())
        assert (fields["satellite"], fields["name"], fields["tune"], fields["track"]) == ("25544", "ISS", "on", "on")
        assert main(["poke", "--config", str(path), "summary"]) == 0
        assert capsys.readouterr().out.startswith("ISS AZ:")
    finally:
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(10) == 0
    assert "Nova TCP server listening on 127.0.0.1 port" in (tmp_path / "log.txt").read_text()
