"""contrib/systemd: the signals the units send are the ones the station (or the Wine launcher) handles, and the
Linux unit's own command lines start, reload and stop a real station (systemd itself is not needed)."""

from __future__ import annotations

import os
import re
import shlex
import signal
import socket
import subprocess
import sys
from pathlib import Path

import pytest

from nfwserver.cli.signals import RELOAD, STOP, signal_actions
from nfwserver.tcp.status_line import parse_status
from tests.conftest import DATA, ROOT
from tests.hamlib_daemons import free_port
from tests.waiting import wait_for

UNITS = ROOT / "contrib" / "systemd"
LAUNCHER = ROOT / "tools" / "wine" / "nfwserver"


def parse_unit(path: Path) -> dict[str, dict[str, list[str]]]:
    """A unit file's sections, each key with its values in order (systemd allows repeated keys)."""
    sections: dict[str, dict[str, list[str]]] = {}
    current: dict[str, list[str]] = {}
    for raw in path.read_text().splitlines():
        line = raw.strip()
        if not line or line.startswith(("#", ";")):
            continue
        if line.startswith("[") and line.endswith("]"):
            current = sections.setdefault(line[1:-1], {})
            continue
        key, _, value = line.partition("=")
        current.setdefault(key.strip(), []).append(value.strip())
    return sections


def kill_signal(command: str) -> signal.Signals:
    """The signal of a ``/bin/kill -SIG $MAINPID`` command line."""
    match = re.fullmatch(r"/bin/kill -([A-Z0-9]+) \$MAINPID", command)
    assert match, command
    return signal.Signals["SIG" + match.group(1)]


def launcher_traps() -> dict[str, set[signal.Signals]]:
    """The Wine launcher's ``trap ACTION SIGNALS`` lines: action -> signals."""
    traps: dict[str, set[signal.Signals]] = {}
    for line in LAUNCHER.read_text().splitlines():
        match = re.fullmatch(r"trap (.+?) ((?:[A-Z][A-Z0-9]+ ?)+)", line.strip())
        if match and match.group(2).split()[0] != "EXIT":
            traps[match.group(1)] = {signal.Signals["SIG" + name] for name in match.group(2).split()}
    return traps


def test_the_linux_unit_sends_the_signals_the_headless_station_handles() -> None:
    service = parse_unit(UNITS / "nfwserver.service")["Service"]
    assert service["Type"] == ["exec"] and service["Restart"] == ["on-failure"]
    assert service["User"] and service["StateDirectory"] == ["nfwserver"]
    start = shlex.split(service["ExecStart"][0])
    assert start[1:3] == ["run", "--headless"]  # headless: SIGHUP reloads
    actions = signal_actions(headless=True)
    assert actions[kill_signal(service["ExecReload"][0])] == RELOAD
    assert "ExecStop" not in service  # systemctl stop sends KillSignal
    assert actions[signal.Signals[service.get("KillSignal", ["SIGTERM"])[0]]] == STOP


def test_the_wine_unit_signals_only_the_launcher_with_signals_it_handles() -> None:
    service = parse_unit(UNITS / "nfwserver-wine.service")["Service"]
    assert service["Restart"] == ["on-failure"] and service["KillMode"] == ["mixed"]  # never python.exe directly
    start = shlex.split(service["ExecStart"][0])
    assert start[0].endswith("/tools/wine/nfwserver") and start[1:3] == ["run", "--headless"]
    assert "NFW_WINE_TIMEOUT=0" in service["Environment"][0].split()  # no time limit on a service
    traps = launcher_traps()
    stop, reload = traps["on_stop"], traps["on_reload"]
    assert signal.Signals[service["KillSignal"][0]] in stop
    assert {signal.SIGTERM, signal.SIGINT, signal.SIGHUP} <= stop
    assert kill_signal(service["ExecReload"][0]) in reload


def _status(port: int) -> dict[str, str]:
    with socket.create_connection(("127.0.0.1", port), timeout=2.0) as sock:
        reader = sock.makefile("rb")
        reader.readline()
        sock.sendall(b"STATUS\r\n")
        return parse_status(reader.readline().decode())


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_the_linux_units_commands_start_reload_stop_and_fail_as_documented(tmp_path) -> None:
    service = parse_unit(UNITS / "nfwserver.service")["Service"]
    dirs = {"%E": tmp_path / "etc", "%S": tmp_path / "lib", "%L": tmp_path / "log"}
    for name in ("ConfigurationDirectory", "StateDirectory", "LogsDirectory"):
        base = {"ConfigurationDirectory": "%E", "StateDirectory": "%S", "LogsDirectory": "%L"}[name]
        (dirs[base] / service[name][0]).mkdir(parents=True)

    def expand(text: str) -> str:
        for spec, path in dirs.items():
            text = text.replace(spec, str(path))
        return text

    port = free_port()
    config = dirs["%E"] / "nfwserver" / "config.toml"
    body = ('[observer]\nlocation = "52.2053,0.1218,20"\n'
            f'[elements]\nfiles = ["{DATA / "visual.txt"}"]\nuse_bundled = false\n'
            f'[server]\nsatellite = 25544\ntune = true\n[tcp]\nenabled = true\nport = {port}\n')
    config.write_text(body)
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    env.update(item.split("=", 1) for item in expand(service["Environment"][0]).split())
    command = [sys.executable, "-m", "nfwserver", *shlex.split(expand(service["ExecStart"][0]))[1:]]
    proc = subprocess.Popen(command, cwd=ROOT, env=env, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE)
    try:
        wait_for(lambda: _status(port)["tune"] == "on", 30.0, "the station to serve with TUNE ON", tolerate=(OSError,))
        config.write_text(body + '[satellites]\nnames = { 25544 = "ZARYA" }\n')
        reload = shlex.split(service["ExecReload"][0].replace("$MAINPID", str(proc.pid)))
        assert subprocess.run(reload).returncode == 0  # systemctl reload
        wait_for(lambda: _status(port)["name"] == "ZARYA", 5.0, "the reloaded name", tolerate=(OSError,))
        proc.send_signal(signal.Signals[service["KillSignal"][0]])  # systemctl stop
        assert proc.wait(float(service["TimeoutStopSec"][0])) == 0  # a clean stop: no restart
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(10)
    assert (dirs["%S"] / "nfwserver" / "state.json").exists()  # the state in StateDirectory
    assert (dirs["%L"] / "nfwserver" / "nfwserver.log").read_text().rstrip().endswith("stopped")
    # A start that fails (the TCP port taken) exits non-zero: Restart=on-failure starts it again.
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", port))
        taken.listen()
        failed = subprocess.run(command, cwd=ROOT, env=env, stdin=subprocess.DEVNULL, capture_output=True,
                                timeout=60)
    assert failed.returncode == 1 and b"Traceback" not in failed.stderr, failed.stderr
