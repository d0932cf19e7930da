"""``nfwserver stop``, ``status`` and a second ``run`` tried as an attacker (or bad luck) would, against real
``nfwserver run --headless`` processes (issue 42 items 9-12, issue 45 items 2-3): a stop while the station is
still starting, a full disk, a forged ``station.json``, a suspended station, a broken configuration file."""

from __future__ import annotations

import contextlib
import ctypes
import json
import os
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from nfwserver.cli.station_channel import StationChannel
from nfwserver.cli.station_process import process_start
from tests.app import test_run_signals
from tests.app.test_stop_command import _cli
from tests.conftest import ROOT
from tests.waiting import wait_for

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux processes, /proc and mounts")
#: The fixture making real ``nfwserver run --headless`` stations in ``tmp_path``.
station = test_run_signals.station

IN_OPEN = 0x20


def _channel(home: Path) -> StationChannel:
    return StationChannel(home / "state" / "nfwserver")


def _described_up(st: test_run_signals.Station) -> None:
    """Wait until the serving station has also described itself as up (just after its TCP port answers)."""
    st.wait_serving()
    wait_for(lambda: _channel(st.home).serving() is not None, 30.0, "the station's description")


@contextlib.contextmanager
def _opened(path: Path) -> Iterator[int]:
    """An inotify descriptor that becomes readable when ``path`` is next opened (Linux)."""
    libc = ctypes.CDLL(None, use_errno=True)
    fd = libc.inotify_init1(0)
    assert fd >= 0 and libc.inotify_add_watch(fd, os.fsencode(path), IN_OPEN) >= 0
    try:
        yield fd
    finally:
        os.close(fd)


def test_stop_reaches_a_station_that_is_still_reading_its_configuration(tmp_path) -> None:
    """#42 item 9: the lock (and the description saying how to stop it) come before anything else ``run`` does,
    so a ``stop`` during start-up finds the station: frozen at the moment it opens its configuration file, it
    already holds the lock; continued and stopped, it starts and stops cleanly (before: no lock until 0.67 s
    in, and ``stop`` said "no station is running" while the station went on)."""
    home = tmp_path
    config = home / "config" / "nfwserver" / "config.toml"
    config.parent.mkdir(parents=True)
    config.write_text('[observer]\nlocation = "JO02ae"\n[elements]\nuse_bundled = false\nstore = "none"\n'
                      f'files = ["{ROOT / "tests" / "data" / "visual.txt"}"]\n')
    env = {**os.environ, "PYTHONPATH": str(ROOT), "XDG_CONFIG_HOME": str(home / "config"),
           "XDG_STATE_HOME": str(home / "state")}
    env.pop("NFW_CONTROL_FILE", None)
    with _opened(config) as watch:
        proc = subprocess.Popen([sys.executable, "-m", "nfwserver", "run", "--headless", "--log-file",
                                 str(home / "nfw.log")], cwd=ROOT, env=env, stdin=subprocess.DEVNULL,
                                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        try:
            os.read(watch, 4096)  # the station opens its configuration
            proc.send_signal(signal.SIGSTOP)
            channel = _channel(home)
            assert channel.running(), "the station reads its configuration before it takes its lock"
            assert channel.verified(channel.info())  # and it has said who it is
            proc.send_signal(signal.SIGCONT)
            result = _cli(home, "stop")
            assert result.returncode == 0, result.stderr
            assert result.stdout == f"stopped the station (process {proc.pid})\n"
            assert proc.wait(10) == 0
            log = (home / "nfw.log").read_text()
            assert "outputs: " in log and log.rstrip().endswith("stopped")  # it finished starting, then stopped
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait(10)


@contextlib.contextmanager
def _small_tmpfs(where: Path) -> Iterator[Path]:
    """A 1 MiB tmpfs mounted at ``where`` (skips the test when mounting is not allowed here)."""
    where.mkdir(parents=True)
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=1m", "tmpfs", str(where)], capture_output=True,
                             check=False)
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {mounted.stderr.decode(errors='replace').strip()}")
    try:
        yield where
    finally:
        subprocess.run(["umount", "-l", str(where)], check=False)


def _fill(directory: Path) -> None:
    """Write ``directory``'s file system full (until ENOSPC)."""
    with contextlib.suppress(OSError), open(directory / "filler", "wb", buffering=0) as filler:
        while True:
            filler.write(b"\0" * 65536)
    with pytest.raises(OSError):
        (directory / "probe").write_bytes(b"x" * 8192)


def test_stop_stops_a_station_whose_disk_is_full(tmp_path) -> None:
    """#42 item 10: the station's state folder on a real, full file system (a 1 MiB tmpfs): ``stop`` signals
    the verified station and needs no space (before: it only wrote its control file, failed, exit 1)."""
    with _small_tmpfs(tmp_path / "state"):
        st = test_run_signals.Station(tmp_path)
        try:
            st.wait_serving()
            _fill(tmp_path / "state")
            result = _cli(tmp_path, "stop")
            assert result.returncode == 0, result.stderr
            assert result.stdout == f"stopped the station (process {st.proc.pid})\n"
            assert st.proc.wait(10) == 0
        finally:
            st.stop()


def test_a_forged_description_makes_stop_write_and_signal_nothing(station, tmp_path) -> None:
    """#42 item 11: ``station.json`` rewritten to name a live ``sleep`` (with its true start time) and a file to
    overwrite as the control file: ``stop`` signals no one and writes nothing, and says why in one sentence
    (before: that file was replaced with "stop")."""
    st = station()
    _described_up(st)  # else its own description, written once up, could replace the forged one
    victim = tmp_path / "precious.txt"
    victim.write_text("the operator's notes\n")
    sleeper = subprocess.Popen(["sleep", "60"])
    try:
        channel = _channel(tmp_path)
        forged = {"pid": sleeper.pid, "start": process_start(sleeper.pid), "control": str(victim), "started": True,
                  "web": None, "tcp": None}
        channel.info_path.write_text(json.dumps(forged))
        result = _cli(tmp_path, "stop", "--timeout", "0.5")
        assert result.returncode == 1 and result.stdout == ""
        assert result.stderr == (f"nfwserver: the station's description {channel.info_path} names process "
                                 f"{sleeper.pid}, which is not the process holding {channel.lock_path}: nothing was "
                                 "done; stop the station from its own console or with Ctrl+C\n")
        assert victim.read_text() == "the operator's notes\n"
        assert not (channel.directory / "control").exists()
        assert sleeper.poll() is None and st.proc.poll() is None and st.status()["tune"] == "on"
    finally:
        sleeper.kill()
        sleeper.wait(10)


def test_a_stop_that_gives_up_on_a_suspended_station_says_what_will_happen(station, tmp_path) -> None:
    """#42 item 12: a SIGSTOPped station has the stop signal when ``stop`` gives up (exit 3), and the sentence
    says so: it stops cleanly as soon as it is continued, which it then does (docs/RELIABILITY.md)."""
    st = station()
    st.wait_serving()
    st.proc.send_signal(signal.SIGSTOP)
    try:
        result = _cli(tmp_path, "stop", "--timeout", "0.5")
        assert result.returncode == 3 and result.stdout == ""
        assert result.stderr == (f"nfwserver: the station (process {st.proc.pid}) was asked to stop but is still "
                                 "running after 0.5 s: it is suspended (SIGSTOP or Ctrl+Z) and has the stop signal, "
                                 "so it will stop cleanly as soon as it is continued "
                                 f"(`kill -CONT {st.proc.pid}`)\n")
    finally:
        st.proc.send_signal(signal.SIGCONT)
    assert st.proc.wait(10) == 0  # as said: a clean stop once continued
    assert "SIGTERM: stopping" in st.log.read_text()


def test_status_and_poke_reach_the_station_while_its_configuration_file_is_broken(station, tmp_path) -> None:
    """#45 item 2: the station's channel says where it listens, so ``status`` and ``poke`` reach it with a TOML
    syntax error in the file; they say in one line what is wrong and that the station runs on its last good
    configuration (before: "configuration refused", exit 1)."""
    st = station()
    _described_up(st)
    st.config.write_text(st.config.read_text() + "[tcp\n")
    status = _cli(tmp_path, "status")
    assert status.returncode == 0, status.stderr
    assert status.stdout.startswith("satellite=25544 ") and " tune=on " in status.stdout
    lines = [line for line in status.stderr.splitlines() if "configuration" in line]  # (and the stale elements')
    assert len(lines) == 1 and lines[0].startswith(f"nfwserver: warning: configuration refused: {st.config}: ")
    assert "not valid TOML" in lines[0] and lines[0].endswith("; the running station runs on its last good "
                                                              "configuration")
    poke = _cli(tmp_path, "poke", "TRACK OFF")
    assert poke.returncode == 0 and poke.stdout == "OK\n" and poke.stderr.splitlines() == lines
    assert st.status()["track"] == "off"
    dashboard = _cli(tmp_path, "dashboard", "--print")  # this station serves no web page: it says so, and the same line
    assert dashboard.returncode == 1 and "serves no web dashboard" in dashboard.stderr
    assert dashboard.stderr.splitlines()[0] == lines[0]


def test_a_second_run_is_refused_before_it_reads_its_configuration(station, tmp_path) -> None:
    """#45 item 3: the lock is the first thing ``run`` looks at, so a second ``run`` says a station is already
    running even when the configuration file is broken (before: "configuration refused", after reading it and
    loading what came before the lock)."""
    st = station()
    st.wait_serving()
    st.config.write_text("[tcp\n")
    second = _cli(tmp_path, "run", "--headless", "--log-file", str(tmp_path / "second.log"))
    assert second.returncode == 1
    assert second.stderr == (f"nfwserver: a station is already running for this user (process {st.proc.pid}): "
                             "`nfwserver stop` stops it\n")
    wait_for(lambda: st.proc.poll() is None, 1.0, "the first station still running")
