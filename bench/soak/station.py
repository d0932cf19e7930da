"""The station under soak: ``python -m nfwserver run --headless`` with real ``rotctld`` and ``rigctld``, the
outages injected into them, an ``nfwserver watch`` beside it, and the process sampled from ``/proc``.

Linux only (``/proc``); the daemons are Debian's ``libhamlib-utils`` (``tests/hamlib_daemons.py``).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from tests.hamlib_daemons import HamlibDaemon, free_port
from tests.waiting import wait_for

ROOT = Path(__file__).resolve().parents[2]
TICKS_PER_S = os.sysconf("SC_CLK_TCK")


@dataclass(frozen=True)
class Sample:
    """The process at one moment: seconds since the start, RSS (MiB), threads, open descriptors, CPU seconds
    used so far (user + system), the log's size (bytes, every rotated file included)."""

    at: float
    rss_mib: float
    threads: int
    fds: int
    cpu_s: float
    log_bytes: int


@dataclass
class Outage:
    """One daemon killed at ``down`` and started again at ``up`` (``time.monotonic()`` seconds; None: not yet, or
    never when the run ended first)."""

    daemon: str
    down: float
    up: float | None = None
    restart_errors: list[str] = field(default_factory=list)  #: why each failed attempt to start it again failed


@dataclass
class Soak:
    """The configuration, the daemons, the process and what was recorded of them."""

    rate_hz: float
    work: Path
    rotctld: HamlibDaemon = field(default_factory=lambda: HamlibDaemon(
        "rotctld", extra=["--set-conf=min_az=0,max_az=450,min_el=0,max_el=90"]))
    rigctld: HamlibDaemon = field(default_factory=lambda: HamlibDaemon("rigctld"))
    tcp_port: int = field(default_factory=free_port)
    web_port: int = field(default_factory=free_port)
    samples: list[Sample] = field(default_factory=list)
    outages: list[Outage] = field(default_factory=list)
    process: subprocess.Popen[bytes] | None = None
    watch: subprocess.Popen[bytes] | None = None
    started: float = 0.0
    stop_s: float | None = None  #: how long SIGTERM took to end the station
    exit_code: int | None = None

    @property
    def log(self) -> Path:
        return self.work / "nfwserver.log"

    def config(self, refresh_hours: float) -> Path:
        """The station's configuration: TUNE, TRACK and tuning on, the ISS, elements re-read every
        ``refresh_hours``."""
        elements = self.work / "elements.txt"
        elements.write_text((ROOT / "tests" / "data" / "visual.txt").read_text())
        path = self.work / "nfwserver.toml"
        path.write_text(
            '[observer]\nlocation = "JO02ae"\n'
            f'[elements]\nfiles = ["{elements}"]\nrefresh_hours = {refresh_hours}\n'
            f'[server]\nrate_hz = {self.rate_hz:g}\nsatellite = 25544\ntune = true\ntrack = true\n'
            'state_file = "none"\n'
            f'[radio]\nbackend = "rigctld"\nport = {self.rigctld.port}\nenabled = true\n'
            f'[rotor]\nbackend = "rotctld"\nport = {self.rotctld.port}\ngeometry = "overlap-450"\n'
            f'[tcp]\nenabled = true\nport = {self.tcp_port}\n'
            f'[web]\nenabled = true\nport = {self.web_port}\nallow = ["127.0.0.0/8"]\n')
        return path

    def start(self, refresh_hours: float) -> None:
        self.rotctld.start()
        self.rigctld.start()
        # A user directory of its own: the single-instance lock, the stored catalog and the state file of this
        # station are not those of any other station of this user.
        env = {**os.environ, "PYTHONPATH": str(ROOT), **{f"XDG_{kind}_HOME": str(self.work / kind.lower())
                                                         for kind in ("STATE", "DATA", "CONFIG", "CACHE")}}
        config = self.config(refresh_hours)
        with open(self.work / "stderr.txt", "wb") as stderr:
            self.process = subprocess.Popen(
                [sys.executable, "-m", "nfwserver", "run", "--headless", "--config", str(config), "--log-file",
                 str(self.log)], cwd=self.work, env=env, stdout=subprocess.DEVNULL, stderr=stderr)
        wait_for(self._listening, 60.0,
                 lambda: f"the station's TCP port; it said: {(self.work / 'stderr.txt').read_text()[-2000:]}")
        self.watch = subprocess.Popen(
            [sys.executable, "-m", "nfwserver", "watch", "--port", str(self.tcp_port)], cwd=self.work, env=env,
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        self.started = time.monotonic()

    def _listening(self) -> bool:
        import socket

        try:
            socket.create_connection(("127.0.0.1", self.tcp_port), timeout=1.0).close()
        except OSError:
            return False
        return True

    def sample(self) -> Sample:
        """Read the process's state from ``/proc``."""
        assert self.process is not None
        pid = self.process.pid
        status = dict(line.split(":", 1) for line in Path(f"/proc/{pid}/status").read_text().splitlines()
                      if ":" in line)
        stat = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        cpu = (int(stat[11]) + int(stat[12])) / TICKS_PER_S  # utime, stime (fields 14 and 15)
        logs = sum(p.stat().st_size for p in self.work.glob("nfwserver.log*"))
        sample = Sample(time.monotonic() - self.started, int(status["VmRSS"].split()[0]) / 1024.0,
                        int(status["Threads"]), len(os.listdir(f"/proc/{pid}/fd")), cpu, logs)
        self.samples.append(sample)
        return sample

    def kill(self, daemon: str, down_s: float, stop: threading.Event) -> None:
        """Kill ``daemon`` (``rotctld`` or ``rigctld``) and start it again on its port after ``down_s``."""
        target = self.rotctld if daemon == "rotctld" else self.rigctld
        outage = Outage(daemon, time.monotonic())
        self.outages.append(outage)
        target.kill()
        stop.wait(down_s)
        while True:  # a restart that fails (its port taken, too slow to listen on a busy machine) is said and retried
            try:
                target.start()
                break
            except Exception as exc:  # noqa: BLE001 -- kept in the outage and said; the daemon must come back
                outage.restart_errors.append(f"{type(exc).__name__}: {exc}")
                print(f"  {daemon} did not start again ({outage.restart_errors[-1]}); retrying", file=sys.stderr)
                if stop.wait(2.0):
                    return
        outage.up = time.monotonic()

    def stop(self) -> None:
        if self.watch is not None:
            self.watch.send_signal(signal.SIGTERM)
            self.watch.wait(10)
        if self.process is not None:
            began = time.monotonic()
            self.process.send_signal(signal.SIGTERM)
            self.exit_code = self.process.wait(60)
            self.stop_s = time.monotonic() - began
        self.rotctld.kill()
        self.rigctld.kill()
