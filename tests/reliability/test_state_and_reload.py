"""Session state across restarts and kills; configuration changed while running; slow element URLs; many files."""

from __future__ import annotations

import http.server
import json
import os
import random
import signal
import subprocess
import sys
import threading
import time
from datetime import datetime, timezone

import pytest

from nfwserver.app.element_sources import fetch_all
from nfwserver.app.session_state import SessionState, StateFile
from nfwserver.app.station import Station
from nfwserver.clock import VirtualClock
from nfwserver.config.loader import parse_config
from nfwserver.core.events import Direction
from nfwserver.fake_dde import FakeDdeSystem
from nfwserver.tracking.elements import load_elements
from tests.conftest import DATA, advance_until
from tests.waiting import wait_for


def test_the_selected_satellite_survives_a_restart(tmp_path) -> None:
    state = tmp_path / "state.json"
    config = parse_config(f'[server]\nstate_file = "{state}"\n')
    clock = VirtualClock(datetime(2026, 5, 8, tzinfo=timezone.utc))

    def started(cfg=config) -> Station:
        station = Station(cfg, clock, transport=FakeDdeSystem().server_transport())
        station.start()
        return station

    first = started()
    assert first.core.command("SAT=27607").ok
    saved = advance_until(clock, lambda: state.exists() and json.loads(state.read_text())["satellite"] == 27607)
    first.stop()
    assert saved and json.loads(state.read_text())["configured"] == 25544
    second = started()
    assert second.core.snapshot().catalog_number == 27607
    second.stop()
    # An edited [server] satellite wins over a choice saved before the edit.
    edited = started(parse_config(f'[server]\nstate_file = "{state}"\nsatellite = 7530\n'))
    assert edited.core.snapshot().catalog_number == 7530
    edited.stop()
    state.write_text("{not json")
    third = started()
    assert third.core.snapshot().catalog_number == 25544  # a broken file means no saved state
    third.stop()


def test_an_unwritable_state_file_is_one_warning_retried_with_backoff_and_cleared_when_writable(tmp_path, caplog):
    """A directory where the state file should be makes every save fail (also for root, unlike chmod)."""
    import logging

    state = tmp_path / "state.json"
    state.mkdir()
    clock = VirtualClock(datetime(2026, 5, 8, tzinfo=timezone.utc))
    station = Station(parse_config(f'[server]\nstate_file = "{state}"\nrate_hz = 5\n'), clock,
                      transport=FakeDdeSystem().server_transport())
    caplog.set_level(logging.INFO)
    station.start()
    try:
        assert station.core.command("SAT=27607").ok
        assert advance_until(clock, lambda: "state-file" in station.core.health.faults())
        advance_until(clock, lambda: False, limit_s=20.0)  # 20 s of ticks at 5 Hz with the file unwritable
        lines = [r for r in caplog.records if "cannot save the session state" in r.getMessage()]
        assert len(lines) == 1 and lines[0].levelno == logging.WARNING
        assert "keeping it in memory" in station.core.health.faults()["state-file"]
        assert station.core.snapshot().catalog_number == 27607  # the choice stays in memory
        state.rmdir()
        assert advance_until(clock, lambda: "state-file" not in station.core.health.faults(), limit_s=120)
        assert json.loads(state.read_text())["satellite"] == 27607
        assert any("state-file: recovered" in r.getMessage() for r in caplog.records)
    finally:
        station.stop()


_SAVER = (
    "import itertools, sys\n"
    "from nfwserver.app.session_state import SessionState, StateFile\n"
    "f = StateFile(sys.argv[1])\n"
    "for k in itertools.count(2):\n"
    "    f.save(SessionState(k))\n"
    "    print(k, flush=True)  # k is on disk\n"
)


@pytest.mark.skipif(sys.platform == "win32", reason="SIGKILL, SIGSTOP")
def test_sigkill_during_state_saves_leaves_the_last_saved_state_and_no_temporary(tmp_path) -> None:
    """Saves are confirmed one by one on stdout, so "saved" is told from "never saved": after the kill
    the file holds the last confirmed state or the one being written, never an older one."""
    state = tmp_path / "state.json"
    StateFile(state).save(SessionState(1))
    state.chmod(0o640)
    mid_write = 0
    for delay in (0.05, None, 0.2, None, None):
        proc = subprocess.Popen([sys.executable, "-c", _SAVER, str(state)], stdout=subprocess.PIPE, text=True)
        first = int(proc.stdout.readline())  # saving has started (the old test often killed before that)
        if delay is None:  # kill while a save is writing: its temporary exists (checked with the saver stopped)
            prefix = f".{state.name}.{proc.pid}."

            def stopped_mid_write(proc: subprocess.Popen[str] = proc, prefix: str = prefix) -> bool:
                if not any(n.startswith(prefix) for n in os.listdir(tmp_path)):
                    return False
                os.kill(proc.pid, signal.SIGSTOP)
                if any(n.startswith(prefix) for n in os.listdir(tmp_path)):
                    return True
                os.kill(proc.pid, signal.SIGCONT)
                return False

            if wait_for(stopped_mid_write, 30.0, "a save caught writing", interval_s=0.0):
                mid_write += 1
        else:
            time.sleep(delay)
        os.kill(proc.pid, signal.SIGKILL)
        confirmed = [first] + [int(line) for line in proc.stdout.read().split()]  # EOF: the saver is dead
        proc.stdout.close()
        proc.wait(10)
        saved = json.loads(state.read_text())["satellite"]
        assert confirmed[-1] <= saved <= confirmed[-1] + 1
        assert StateFile(state).load().satellite == saved  # opening it removes the killed writer's temporary
        assert not list(tmp_path.glob(".state.json.*.tmp"))
        assert state.stat().st_mode & 0o777 == 0o640
    assert mid_write == 3


def test_configuration_changed_while_running(tmp_path) -> None:
    """The watcher runs on the station's virtual clock: no real sleeps, only clock steps."""
    path = tmp_path / "c.toml"
    path.write_text('[observer]\nlocation = "JO02ae"\n[server]\nrate_hz = 5\nstate_file = "none"\n')
    from nfwserver.config.loader import load_config

    clock = VirtualClock(datetime(2026, 5, 8, tzinfo=timezone.utc))
    station = Station(load_config(path), clock, transport=FakeDdeSystem().server_transport())
    notes = []
    station.core.events.subscribe(lambda e: notes.append(e) if e.direction is Direction.INFO else None)
    station.start()
    station.watch_config(str(path), interval_s=0.5)
    state = station.core.state
    try:
        before = state.observer
        path.write_text('[observer]\nlocation = "QF56od"\n[server]\nrate_hz = 500\n')  # invalid rate
        assert advance_until(clock, lambda: any("refused" in n.text for n in notes))
        assert any("[server] rate_hz" in n.text for n in notes)
        assert state.observer == before and state.rate_hz == 5  # old configuration kept
        path.write_text('[observer]\nlocation = "QF56od"\n[server]\nrate_hz = 10\nstate_file = "none"\n'
                        '[rotor]\nbackend = "sim"\n')
        assert advance_until(clock, lambda: any("reloaded" in n.text for n in notes))
        assert state.observer.latitude_deg < 0 and state.rate_hz == 10
        assert any("restart to apply [rotor]" in n.text for n in notes)
        # Restoring what is running needs no restart, and the message says so.
        notes.clear()
        path.write_text('[observer]\nlocation = "QF56od"\n[server]\nrate_hz = 10\nstate_file = "none"\n')
        assert advance_until(clock, lambda: any("reloaded" in n.text for n in notes))
        assert not any("restart" in n.text for n in notes)
    finally:
        station.stop()


@pytest.mark.parametrize("half_saved", ["", "\n  \n", "# nfwserver configuration\n# [observer]\n", "\ufeff"])
def test_an_empty_or_half_saved_file_is_refused_and_the_running_configuration_stays(tmp_path, half_saved) -> None:
    """An editor mid-save leaves an empty or comment-only file: it never resets the station to defaults.
    The refusal shows as the ``config`` fault until a whole file is applied, which clears it."""
    path = tmp_path / "c.toml"
    path.write_text('[observer]\nlocation = "QF56od"\n[server]\nrate_hz = 5\nstate_file = "none"\n')
    from nfwserver.config.loader import load_config

    clock = VirtualClock(datetime(2026, 5, 8, tzinfo=timezone.utc))
    station = Station(load_config(path), clock, transport=FakeDdeSystem().server_transport())
    notes = []
    station.core.events.subscribe(lambda e: notes.append(e) if e.direction is Direction.INFO else None)
    station.start()
    station.watch_config(str(path), interval_s=0.5)
    state = station.core.state
    try:
        before = state.observer
        path.write_text(half_saved, encoding="utf-8")
        assert advance_until(clock, lambda: any("refused" in n.text for n in notes))
        assert any("has no settings" in n.text for n in notes)
        assert state.observer == before and state.observer.latitude_deg < 0 and state.rate_hz == 5
        assert "has no settings" in station.core.health.faults()["config"]
        path.write_text('[observer]\nlocation = "QF56od"\n[server]\nrate_hz = 10\nstate_file = "none"\n')
        assert advance_until(clock, lambda: any("reloaded" in n.text for n in notes))
        assert state.rate_hz == 10 and "config" not in station.core.health.faults()
    finally:
        station.stop()


def test_a_slow_element_url_times_out_and_the_rest_loads(tmp_path) -> None:
    class Slow(http.server.BaseHTTPRequestHandler):
        def do_GET(self):
            time.sleep(2.0)
            self.send_response(200)
            self.end_headers()

        def log_message(self, *args):
            pass

    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Slow)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    try:
        started = time.monotonic()
        result = fetch_all(files=(str(DATA / "visual.txt"),), urls=(f"http://127.0.0.1:{server.server_address[1]}/x",),
                           use_bundled=False, timeout_s=0.3)
        assert time.monotonic() - started < 1.5
        assert len(result.sets) == 148 and len(result.failed) == 1
    finally:
        server.shutdown()
        server.server_close()


def test_ten_thousand_generated_element_files_never_raise() -> None:
    rng = random.Random(2026)
    lines = (DATA / "visual.txt").read_text().splitlines()
    junk = ["", "junk", "1 ", "2 x", "Satellite: X", "Mean motion: 3", "0 NAME", "\x00\x01", "{",
            "NORAD_CAT_ID,MEAN_MOTION"]
    loaded = rejected = 0
    for _ in range(10_000):
        pieces = []
        for _ in range(rng.randint(0, 8)):
            choice = rng.random()
            if choice < 0.5:
                k = rng.randrange(0, len(lines) - 2, 3)
                block = lines[k : k + 3]
                if rng.random() < 0.3:  # corrupt one character
                    i = rng.randrange(3)
                    j = rng.randrange(len(block[i]))
                    block[i] = block[i][:j] + rng.choice("0123456789 -+.xZ") + block[i][j + 1 :]
                pieces += block
            else:
                pieces.append(rng.choice(junk))
        result = load_elements("\n".join(pieces), "generated")
        loaded += len(result.sets)
        rejected += len(result.rejected)
        assert all(r.reason for r in result.rejected)
    assert loaded > 10_000 and rejected > 1_000
