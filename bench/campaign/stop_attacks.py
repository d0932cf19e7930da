"""``nfwserver stop`` tried as an attacker would (issue 42 items 9, 11, 12), against real
``nfwserver run --headless`` processes in a temporary home, a round at a time in turn:

- **during start-up**: ``stop`` started a seeded random 0-1.5 s after ``run``; it must stop the station (exit 0,
  the station's exit 0), or -- only when it came before the station's lock -- say none is running;
- **forged description**: ``station.json`` rewritten to name a live ``sleep`` (its true start time) and a file as
  the control file; ``stop`` must signal no one and write nothing, and the station must run on;
- **suspended**: the station stopped with ``SIGSTOP``; ``stop --timeout 0.5`` must exit 3, and the station, once
  continued, must stop cleanly as the sentence says;
- **full disk**: the state folder on a 1 MiB tmpfs written full while the station runs; ``stop`` must stop it
  (exit 0, the station's exit 0).  Needs the right to mount (root); otherwise noted and not counted.

Data lost counts every broken promise: a file written, a process signalled, a station left running after a
``stop`` that said it was stopped, or not stopped after a sentence that said it would be.
"""

from __future__ import annotations

import contextlib
import json
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

from bench.campaign.fuzz_elements import ROOT
from bench.campaign.tally import Tally
from nfwserver.cli.station_channel import StationChannel
from nfwserver.cli.station_process import process_start

#: Real seconds a station may take to start or to stop before the round counts it as lost.
LIMIT_S = 60.0


class _Home:
    """A temporary user (XDG directories) with a small configuration: no TCP, the visual elements, no store."""

    def __init__(self, where: Path) -> None:
        self.where = where
        config = where / "config" / "nfwserver" / "config.toml"
        config.parent.mkdir(parents=True, exist_ok=True)
        config.write_text('[observer]\nlocation = "JO02ae"\n[elements]\nuse_bundled = false\nstore = "none"\n'
                          f'files = ["{ROOT / "tests" / "data" / "visual.txt"}"]\n[tcp]\nenabled = false\n')
        self.env = {**os.environ, "PYTHONPATH": str(ROOT), "XDG_CONFIG_HOME": str(where / "config"),
                    "XDG_STATE_HOME": str(where / "state")}
        self.env.pop("NFW_CONTROL_FILE", None)
        self.channel = StationChannel(where / "state" / "nfwserver")

    def run(self) -> subprocess.Popen[bytes]:
        return subprocess.Popen([sys.executable, "-m", "nfwserver", "run", "--headless", "--log-file",
                                 str(self.where / "nfw.log")], cwd=ROOT, env=self.env, stdin=subprocess.DEVNULL,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def stop(self, *args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run([sys.executable, "-m", "nfwserver", "stop", *args], cwd=ROOT, env=self.env,
                              capture_output=True, text=True, timeout=LIMIT_S + 30, stdin=subprocess.DEVNULL)

    def started(self, proc: subprocess.Popen[bytes]) -> bool:
        """Wait for the station to describe itself as up; False if it exited or took too long."""
        deadline = time.monotonic() + LIMIT_S
        while proc.poll() is None and time.monotonic() < deadline:
            info = self.channel.info()
            if info is not None and info.started and self.channel.verified(info):
                return True
            time.sleep(0.05)
        return False


def _ended(proc: subprocess.Popen[bytes], timeout_s: float = LIMIT_S) -> int | None:
    try:
        return proc.wait(timeout_s)
    except subprocess.TimeoutExpired:
        return None


def _during_start(tally: Tally, home: _Home, rng: random.Random) -> None:
    delay = rng.uniform(0.0, 1.5)
    started = time.monotonic()
    proc = home.run()
    time.sleep(max(0.0, started + delay - time.monotonic()))
    result = home.stop()
    if result.returncode == 0:
        tally.extra["start-up: stopped"] = tally.extra.get("start-up: stopped", 0) + 1
        if _ended(proc, 10.0) != 0:
            tally.loss(f"stop said stopped {delay:.2f} s into the start, the station went on or did not exit 0")
    elif "no station is running" in result.stderr:
        tally.extra["start-up: before the lock"] = tally.extra.get("start-up: before the lock", 0) + 1
        tally.note(f"stop {delay:.2f} s after run came before its lock")
        if home.started(proc):
            home.stop()
    else:
        tally.loss(f"stop {delay:.2f} s into the start: exit {result.returncode}: {result.stderr.strip()}")
    if _ended(proc) is None:
        proc.kill()
        tally.loss("the station never ended")


def _forged(tally: Tally, home: _Home, rng: random.Random) -> None:
    proc = home.run()
    sleeper = subprocess.Popen(["sleep", "120"])
    victim = home.where / "precious.txt"
    victim.write_text("the operator's notes\n")
    try:
        if not home.started(proc):
            tally.loss("the station did not start")
            return
        start = process_start(sleeper.pid) if rng.random() < 0.8 else rng.randrange(9**9)  # true, or made up
        forged = {"pid": sleeper.pid, "start": start,
                  "control": str(victim), "started": True, "web": "http://evil.example/", "tcp": ["192.0.2.1", 1]}
        home.channel.info_path.write_text(json.dumps(forged))
        result = home.stop("--timeout", "0.5")
        if result.returncode != 1 or "which is not the process holding" not in result.stderr:
            tally.loss(f"a forged description: stop exit {result.returncode}: {result.stderr.strip()}")
        if victim.read_text() != "the operator's notes\n" or (home.channel.directory / "control").exists():
            tally.loss("a forged description made stop write a file")
        if sleeper.poll() is not None or proc.poll() is not None:
            tally.loss("a forged description made stop signal a process")
    finally:
        sleeper.kill()
        sleeper.wait(10)
        proc.terminate()
        _ended(proc)


def _suspended(tally: Tally, home: _Home, rng: random.Random) -> None:
    proc = home.run()
    try:
        if not home.started(proc):
            tally.loss("the station did not start")
            return
        proc.send_signal(signal.SIGSTOP)
        result = home.stop("--timeout", "0.5")
        if result.returncode != 3 or "as soon as it is continued" not in result.stderr:
            tally.loss(f"stop of a suspended station: exit {result.returncode}: {result.stderr.strip()}")
        time.sleep(rng.uniform(0.0, 0.5))  # suspended a while longer, as an operator would leave it
        proc.send_signal(signal.SIGCONT)
        if _ended(proc) != 0:
            tally.loss("a suspended station, continued, did not stop cleanly as stop said it would")
    finally:
        if proc.poll() is None:
            proc.send_signal(signal.SIGCONT)
            proc.kill()
            proc.wait(10)


def _full_disk(tally: Tally, home: _Home, rng: random.Random) -> bool:
    """The full-disk round; False when no tmpfs could be mounted (the round is then not counted)."""
    state = home.where / "state"
    state.mkdir(parents=True, exist_ok=True)
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=1m", "tmpfs", str(state)], capture_output=True,
                      check=False).returncode != 0:
        tally.note("full disk: no tmpfs could be mounted here; not run")
        return False
    try:
        proc = home.run()
        if not home.started(proc):
            tally.loss("the station did not start")
        else:
            with contextlib.suppress(OSError), open(state / "filler", "wb", buffering=0) as filler:
                while True:
                    filler.write(b"\0" * rng.choice((4096, 65536)))
            result = home.stop()
            if result.returncode != 0 or _ended(proc, 10.0) != 0:
                tally.loss(f"full disk: stop exit {result.returncode}: {result.stderr.strip()}")
        if proc.poll() is None:
            proc.kill()
            proc.wait(10)
    finally:
        subprocess.run(["umount", "-l", str(state)], check=False)
    return True


ATTACKS = (_during_start, _forged, _suspended, _full_disk)


def run_stop_attacks(tally: Tally, rounds: int, seed: int, workdir: Path) -> None:
    """``rounds`` rounds of each attack, in turn, each in a fresh temporary home."""
    if not sys.platform.startswith("linux"):
        tally.note("Linux processes only: not run")
        return
    rng = random.Random(seed)
    for k in range(rounds * len(ATTACKS)):
        attack = ATTACKS[k % len(ATTACKS)]
        home = _Home(workdir / f"stop-{k}")
        if attack(tally, home, rng) is not False:
            tally.tried += 1
