"""SIGKILL during writes: ``nfwserver elements update`` writing the element store, and a process saving the
session state file as fast as it can, killed at seeded random moments and -- every other round -- at the
moment its temporary exists (the process stopped with SIGSTOP first, so the moment cannot slip).

Whole afterwards means: opening the file removes the killed writer's temporary; the store reads with no
rejected set and holds the old catalog or the complete new one; the state file holds the last save the
writer confirmed or the one it was writing; permissions are those the file had.
"""

from __future__ import annotations

import json
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

from bench.campaign.fuzz_elements import ROOT, SOURCE_SETS
from bench.campaign.tally import Tally
from nfwserver.app.element_store import ElementStore
from nfwserver.app.session_state import SessionState, StateFile
from nfwserver.tracking.elements import load_element_file

NEW_SETS = ROOT / "tests" / "data" / "active.txt"
SAVER = ("import itertools, sys\n"
         "from nfwserver.app.session_state import SessionState, StateFile\n"
         "f = StateFile(sys.argv[1])\n"
         "for k in itertools.count(2):\n"
         "    f.save(SessionState(k))\n"
         "    print(k, flush=True)\n")


def _stop_when_writing(proc: subprocess.Popen, directory: Path, name: str, limit_s: float) -> bool:
    """SIGSTOP ``proc`` once its temporary for ``name`` exists; True if it was stopped mid-write."""
    prefix = f".{name}.{proc.pid}."
    deadline = time.monotonic() + limit_s
    while proc.poll() is None and time.monotonic() < deadline:
        if any(n.startswith(prefix) for n in os.listdir(directory)):
            os.kill(proc.pid, signal.SIGSTOP)
            if any(n.startswith(prefix) for n in os.listdir(directory)):
                return True
            os.kill(proc.pid, signal.SIGCONT)
    return False


def _kill(proc: subprocess.Popen) -> None:
    if proc.poll() is None:
        os.kill(proc.pid, signal.SIGKILL)
    proc.wait(10)


def run_store_kills(tally: Tally, rounds: int, seed: int, workdir: Path) -> None:
    rng = random.Random(seed)
    store = workdir / "killed-store.txt"
    old_sets = load_element_file(SOURCE_SETS).sets
    old_text = "".join(s.tle_text() for s in old_sets)
    new_numbers = {s.catalog_number for s in load_element_file(NEW_SETS).sets} | {s.catalog_number for s in old_sets}
    mid_write = 0
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    for k in range(rounds):
        store.write_text(old_text)
        store.chmod(0o644)
        tally.tried += 1
        proc = subprocess.Popen([sys.executable, "-m", "nfwserver", "elements", "update", str(NEW_SETS),
                                 "--store", str(store)], cwd=ROOT, env=env,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        if k % 2 == 0:
            mid_write += _stop_when_writing(proc, workdir, store.name, 60.0)
        else:
            time.sleep(rng.uniform(0.05, 2.0))
        _kill(proc)
        ElementStore(store)  # opening it removes the killed writer's temporary
        if list(workdir.glob(f".{store.name}.*.tmp")):
            tally.loss("a temporary survived opening the store")
        loaded = load_element_file(store)
        numbers = {s.catalog_number for s in loaded.sets}
        if loaded.rejected or numbers not in ({s.catalog_number for s in old_sets}, new_numbers):
            tally.loss(f"round {k}: the store holds {len(numbers)} sets, {len(loaded.rejected)} unreadable")
        if store.stat().st_mode & 0o777 != 0o644:
            tally.loss(f"round {k}: permissions became {store.stat().st_mode & 0o777:o}")
    tally.extra["kills inside the write"] = mid_write


def run_state_kills(tally: Tally, rounds: int, seed: int, workdir: Path) -> None:
    rng = random.Random(seed + 1)
    state = workdir / "killed-state.json"
    StateFile(state).save(SessionState(1))
    state.chmod(0o640)
    mid_write = 0
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    for k in range(rounds):
        tally.tried += 1
        proc = subprocess.Popen([sys.executable, "-c", SAVER, str(state)], cwd=ROOT, env=env,
                                stdout=subprocess.PIPE, text=True)
        first = int(proc.stdout.readline())  # saving has started
        if k % 2 == 0:
            mid_write += _stop_when_writing(proc, workdir, state.name, 30.0)
        else:
            time.sleep(rng.uniform(0.0, 0.5))
        _kill(proc)
        confirmed = [first] + [int(line) for line in proc.stdout.read().split()]
        proc.stdout.close()
        try:
            saved = json.loads(state.read_text())["satellite"]
        except (ValueError, KeyError) as exc:
            tally.loss(f"round {k}: the state file is not whole ({exc})")
            continue
        if not confirmed[-1] <= saved <= confirmed[-1] + 1:
            tally.loss(f"round {k}: the file holds {saved}, the last confirmed save was {confirmed[-1]}")
        if StateFile(state).load().satellite != saved or list(workdir.glob(f".{state.name}.*.tmp")):
            tally.loss(f"round {k}: reopening changed the state or left a temporary")
        if state.stat().st_mode & 0o777 != 0o640:
            tally.loss(f"round {k}: permissions became {state.stat().st_mode & 0o777:o}")
    tally.extra["kills inside the write"] = mid_write
