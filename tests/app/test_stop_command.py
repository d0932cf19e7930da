"""``nfwserver stop`` and ``nfwserver dashboard`` against a real ``nfwserver run --headless`` process, through the
station's own channel (lock, description, control file); one station per user; ``config edit``/``init --web``;
the windowless program's output."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import urllib.request
from pathlib import Path

import pytest

from nfwserver.cli import main
from nfwserver.cli.station_channel import StationChannel
from nfwserver.cli.windowless import TailText
from tests.app import test_run_signals
from tests.conftest import ROOT
from tests.waiting import wait_for

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX processes (Windows: tests/windows)")
#: The fixture making real ``nfwserver run --headless`` stations in ``tmp_path``.
station = test_run_signals.station


def _cli(home: Path, *args: str, env: dict[str, str] | None = None,
         timeout_s: float = 60.0) -> subprocess.CompletedProcess[str]:
    """``nfwserver ARGS`` as the user runs it, with ``home``'s XDG directories (those the Station uses)."""
    base = {**os.environ, "PYTHONPATH": str(ROOT), "XDG_CONFIG_HOME": str(home / "config"),
            "XDG_STATE_HOME": str(home / "state")}
    return subprocess.run([sys.executable, "-m", "nfwserver", *args], cwd=ROOT, env={**base, **(env or {})},
                          capture_output=True, text=True, timeout=timeout_s, stdin=subprocess.DEVNULL)


def test_stop_asks_the_station_through_its_channel_and_returns_once_it_has_stopped(station, tmp_path) -> None:
    st = station()
    st.wait_serving()
    assert st.ask("SAT=694") == "OK"  # live state that a clean stop saves
    result = _cli(tmp_path, "stop")
    assert result.returncode == 0, result.stderr
    assert result.stdout == f"stopped the station (process {st.proc.pid})\n" and result.stderr == ""
    assert st.proc.wait(10) == 0  # a clean exit, not a kill
    log = st.log.read_text()
    assert "SIGTERM: stopping" in log  # the verified station was signalled: nothing written (#42 item 10)
    assert not (tmp_path / "state" / "nfwserver" / "control").exists()
    assert log.rstrip().endswith("stopped")
    assert json.loads(st.state.read_text())["satellite"] == 694
    channel = StationChannel(tmp_path / "state" / "nfwserver")
    assert not channel.running() and channel.info() is None  # nothing left that says "running"


def test_stop_with_no_station_says_so_in_one_sentence(tmp_path) -> None:
    result = _cli(tmp_path, "stop")
    assert result.returncode == 1 and result.stdout == ""
    assert result.stderr == "nfwserver: no station is running for this user: nothing to stop\n"


def test_a_killed_station_leaves_nothing_running_behind(station, tmp_path) -> None:
    st = station()
    st.wait_serving()
    os.kill(st.proc.pid, signal.SIGKILL)
    st.proc.wait(10)
    channel = StationChannel(tmp_path / "state" / "nfwserver")
    assert channel.info() is not None  # the description outlives a kill ...
    assert not channel.running()  # ... but the lock, which says whether one runs, does not
    result = _cli(tmp_path, "stop")
    assert result.returncode == 1 and "no station is running" in result.stderr
    again = subprocess.Popen(  # and the next station of that user starts
        [sys.executable, "-m", "nfwserver", "run", "--headless", "--log-file", str(tmp_path / "again.log")],
        cwd=ROOT, env={**os.environ, "PYTHONPATH": str(ROOT), "XDG_CONFIG_HOME": str(tmp_path / "config"),
                       "XDG_STATE_HOME": str(tmp_path / "state")}, stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        def described() -> bool:  # one read: the new station removes the dead one's description, then writes its own
            info = channel.info()
            return info is not None and info.pid == again.pid

        wait_for(described, 30.0, "the new station")
        assert _cli(tmp_path, "stop").returncode == 0 and again.wait(10) == 0
    finally:
        if again.poll() is None:
            again.kill()
            again.wait(10)


def test_a_second_station_of_the_same_user_is_refused_naming_the_first(station, tmp_path) -> None:
    st = station()
    st.wait_serving()
    second = _cli(tmp_path, "run", "--headless", "--log-file", str(tmp_path / "second.log"), "--duration", "30")
    assert second.returncode == 1
    assert second.stderr.strip().splitlines()[-1] == (
        f"nfwserver: a station is already running for this user (process {st.proc.pid}): `nfwserver stop` stops it")
    assert st.proc.poll() is None and st.status()["tune"] == "on"  # the first one never noticed


def test_dashboard_prints_the_running_stations_address(station, tmp_path) -> None:
    st = station(extra="[web]\nenabled = true\nport = 0\n")
    st.wait_serving()
    result = _cli(tmp_path, "dashboard", "--print")
    assert result.returncode == 0, result.stderr
    url = result.stdout.strip()
    assert url.startswith("http://127.0.0.1:") and not url.endswith(":0/")
    with urllib.request.urlopen(url, timeout=10) as reply:
        assert reply.status == 200 and b"<html" in reply.read(4096).lower()


def test_dashboard_without_a_web_page_or_a_station_says_why(station, tmp_path) -> None:
    none = _cli(tmp_path, "dashboard", "--print")
    assert none.returncode == 1 and none.stdout == "" and "no station is running" in none.stderr
    st = station()  # [web] not enabled
    st.wait_serving()
    off = _cli(tmp_path, "dashboard", "--print")
    assert off.returncode == 1 and off.stdout == ""
    assert "serves no web dashboard: `nfwserver config set web.enabled true`" in off.stderr


def test_config_edit_writes_a_missing_file_from_the_template_and_opens_it_in_the_editor(tmp_path) -> None:
    opened = tmp_path / "opened.txt"
    editor = tmp_path / "editor.py"
    editor.write_text(f"import sys\nopen({str(opened)!r}, 'a').write(sys.argv[1] + '\\n')\n")
    result = _cli(tmp_path, "config", "edit", env={"VISUAL": "", "EDITOR": f"{sys.executable} {editor}"})
    config = tmp_path / "config" / "nfwserver" / "config.toml"
    assert result.returncode == 0, result.stderr
    assert result.stdout == f"{config} (written from the template)\n"
    assert opened.read_text() == f"{config}\n" and "[observer]" in config.read_text()
    config.write_text("# mine\n")
    again = _cli(tmp_path, "config", "edit", env={"VISUAL": f"{sys.executable} {editor}"})
    assert again.returncode == 0 and again.stdout == f"{config}\n" and config.read_text() == "# mine\n"
    failing = _cli(tmp_path, "config", "edit", env={"VISUAL": "false"})
    assert failing.returncode == 1 and "the editor 'false' exited with status 1" in failing.stderr


def test_config_init_web_serves_the_dashboard_and_keep_leaves_a_file_alone(tmp_path) -> None:
    config = tmp_path / "config" / "nfwserver" / "config.toml"
    first = _cli(tmp_path, "config", "init", "--web", "--keep")
    assert first.returncode == 0 and first.stdout == f"{config}\n"
    shown = _cli(tmp_path, "config", "show")
    assert shown.returncode == 0 and any(line.split()[:3] == ["enabled", "=", "true"]
                                         for line in shown.stdout.split("[web]", 1)[1].splitlines()[:3])
    config.write_text("# changed by the user\n")
    kept = _cli(tmp_path, "config", "init", "--web", "--keep")
    assert kept.returncode == 0 and config.read_text() == "# changed by the user\n"
    refused = _cli(tmp_path, "config", "init", "--web")
    assert refused.returncode == 1 and "already exists" in refused.stderr


def test_a_windowless_run_keeps_its_output_bounded_and_returns_usage_errors(monkeypatch) -> None:
    tail = TailText(limit=10)
    tail.write("0123456789abc")
    assert tail.getvalue() == "3456789abc"
    monkeypatch.setattr(sys, "stdout", None)
    monkeypatch.setattr(sys, "stderr", None)
    assert main(["stop", "--bogus"]) == 2  # no SystemExit out of a program with no console to print it on
    assert isinstance(sys.stderr, TailText) and "unrecognized arguments: --bogus" in sys.stderr.getvalue()


def test_a_windowless_run_that_fails_unexpectedly_reports_the_failure(monkeypatch) -> None:
    from nfwserver.cli import config_command

    def broken(args) -> int:
        raise RuntimeError("something nobody expected")

    monkeypatch.setattr(config_command, "run_path", broken)
    monkeypatch.setattr(sys, "stdout", None)
    monkeypatch.setattr(sys, "stderr", None)
    assert main(["config", "path"]) == 1  # not a traceback into nowhere and a silent exit
    assert "RuntimeError: something nobody expected" in sys.stderr.getvalue()


#: A process that holds the user's station channel as a station does, but never stops (it ignores SIGTERM and
#: never reads its control file: a station stuck while stopping); it says "started" only when its stdin gets a
#: line, and exits at EOF.
STUCK = """
import os, signal, sys
signal.signal(signal.SIGTERM, lambda *_: None)
from pathlib import Path
from nfwserver.cli.station_channel import StationChannel, StationInfo
channel = StationChannel(Path(sys.argv[1]))
assert channel.claim()
from nfwserver.cli.station_process import process_start
channel.describe(StationInfo(os.getpid(), process_start(os.getpid())))
print("claimed", flush=True)
sys.stdin.readline()
channel.describe(StationInfo(os.getpid(), process_start(os.getpid()), "http://127.0.0.1:8091/", started=True))
print("started", flush=True)
sys.stdin.readline()
"""


def _stuck(tmp_path: Path) -> subprocess.Popen[str]:
    proc = subprocess.Popen([sys.executable, "-c", STUCK, str(tmp_path / "state" / "nfwserver")], cwd=ROOT,
                            env={**os.environ, "PYTHONPATH": str(ROOT)}, stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True)
    assert proc.stdout is not None and proc.stdout.readline() == "claimed\n"
    return proc


def test_a_station_that_does_not_stop_in_time_gets_its_own_exit_status(tmp_path) -> None:
    stuck = _stuck(tmp_path)
    try:
        result = _cli(tmp_path, "stop", "--timeout", "0.5")
        assert result.returncode == 3 and result.stdout == ""
        assert result.stderr == (f"nfwserver: the station (process {stuck.pid}) was asked to stop but is still "
                                 "running after 0.5 s: it has the stop signal and will stop once it finishes what "
                                 "it is doing (its log says what)\n")
    finally:
        stuck.kill()
        stuck.wait(10)


def test_dashboard_waits_for_a_station_that_is_still_starting_and_says_so(tmp_path) -> None:
    stuck = _stuck(tmp_path)
    try:
        starting = _cli(tmp_path, "dashboard", "--print", "--wait", "0.5")
        assert starting.returncode == 1 and starting.stdout == ""  # not "serves no web dashboard": not up yet
        assert starting.stderr == ("nfwserver: the station has not finished starting after 0.5 s; try again in a "
                                   "moment\n")
        assert stuck.stdin is not None and stuck.stdout is not None
        stuck.stdin.write("go\n")
        stuck.stdin.flush()
        assert stuck.stdout.readline() == "started\n"
        up = _cli(tmp_path, "dashboard", "--print", "--wait", "0.5")
        assert up.returncode == 0 and up.stdout == "http://127.0.0.1:8091/\n", up.stderr
    finally:
        stuck.kill()
        stuck.wait(10)


def test_a_description_that_cannot_be_written_is_said_once_and_again_when_it_can(tmp_path, caplog) -> None:
    """The station runs on without its description (a `stop` then cannot find it): one warning for the episode,
    one line when it is written again; nothing is swallowed silently."""
    import logging

    from nfwserver.cli.station_channel import StationInfo

    channel = StationChannel(tmp_path)
    assert channel.claim()
    try:
        channel.info_path.mkdir()  # a directory where the file should be: every replace fails
        caplog.set_level(logging.INFO, logger="nfwserver.cli.station_channel")
        for _ in range(3):
            channel.describe(StationInfo(os.getpid()))
        warnings = [r for r in caplog.records if r.levelno == logging.WARNING]
        assert len(warnings) == 1 and "cannot write the station's description" in warnings[0].getMessage()
        channel.info_path.rmdir()
        channel.describe_again()  # what the control file's watcher calls at each look
        assert json.loads(channel.info_path.read_text())["pid"] == os.getpid()
        assert "is written again" in caplog.text
        channel.info_path.unlink()
        channel.describe_again()  # written: nothing to do
        assert not channel.info_path.exists()
    finally:
        channel.release()
