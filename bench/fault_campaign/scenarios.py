"""The faults of the campaign: how each is caused, how its cause ends, and what "working" means.

Each :class:`Fault` names the health link that must show it in STATUS while it lasts (``link``; None
for a fault that must not disturb anything an operator sees), injects its cause into a running
:class:`~bench.fault_campaign.rig.FaultRig`, ends it, and says per tick whether the output it hits
works again (:attr:`Fault.works`).
"""

from __future__ import annotations

import math
import os
import socket
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass

from bench.fault_campaign.rig import ELEMENTS, ISS, ROOT, FaultRig, LorisCounts, TickRecord
from nfwserver.config.loader import parse_config
from nfwserver.tracking.elements import load_element_file, load_elements
from nfwserver.tracking.tle import tle_checksum


@dataclass(frozen=True)
class Fault:
    name: str  #: what an operator would call it
    link: str | None  #: the health link STATUS names while it lasts
    inject: Callable[[FaultRig], None]
    remove: Callable[[FaultRig], None]
    works: Callable[[FaultRig, TickRecord], bool]
    duration_s: float = 20.0  #: how long the cause lasts (virtual seconds)
    feed_may_stop: bool = False  #: the Nova feed itself is what fails (silent ticks are the fault)
    real_time: bool = False  #: ticks paced at real time (a real rotor turns in real time)


# -- what "works" means -----------------------------------------------------------------------------------
def _ask(port: int, command: bytes) -> list[str]:
    with socket.create_connection(("127.0.0.1", port), timeout=2.0) as s:
        s.sendall(command)
        data = b""
        while data.count(b"\n") < (2 if command == b"p\n" else 1):
            chunk = s.recv(4096)
            if not chunk:
                break
            data += chunk
    return data.decode().split()


def feed_works(rig: FaultRig, record: TickRecord) -> bool:
    return record.published


def feed_and_easycomm_current(rig: FaultRig, record: TickRecord) -> bool:
    """The feed publishes and EasyComm never wrote a line for a tick other than the current one."""
    return record.published and rig.stale_easycomm == 0


def easycomm_works(rig: FaultRig, record: TickRecord) -> bool:
    """EasyComm writes while the satellite is up (it never reads its port, so a missing adapter shows
    only when a line is owed)."""
    sample = rig.station.core.tracker.last_sample
    up = sample is not None and sample.above_horizon
    return "easycomm" not in record.faults and (bool(record.easycomm) or not up or rig.index % 3 != 0)


def rotor_works(rig: FaultRig, record: TickRecord) -> bool:
    """The rotor follows: no rotor fault, and the real daemon's rotor is within 15 degrees of where the
    driver sent it or closing on it (a restarted dummy rotctld starts at 0 degrees and slews back)."""
    rotor = rig.station.rotor
    if rotor is None or "rotor" in record.faults or "rotctld" in record.faults:
        rig.rotor_distance = float("inf")  # the first reading after the fault counts as closing
        return False
    commanded = rotor.driver.commanded_position
    if commanded is None:
        return False
    az, el = (float(v) for v in _ask(rig.rotctld.port, b"p\n")[:2])
    distance = math.hypot(az - commanded[0], el - commanded[1])
    closing = distance < rig.rotor_distance - 0.5
    rig.rotor_distance = distance
    return distance < 15.0 or closing


def rotor_moving(rig: FaultRig, record: TickRecord) -> bool:
    """Stricter than :func:`rotor_works` (for a still target): the real rotor is within 15 degrees of its target
    or is seen closing on it now, between two readings of the daemon a quarter of a real second apart (the dummy
    turns about 1.5 degrees in that time)."""
    rotor = rig.station.rotor
    if rotor is None or rotor.driver.commanded_position is None or {"rotor", "rotctld"} & set(record.faults):
        return False
    commanded = rotor.driver.commanded_position

    def distance() -> float:
        az, el = (float(v) for v in _ask(rig.rotctld.port, b"p\n")[:2])
        return math.hypot(az - commanded[0], el - commanded[1])

    first = distance()
    if first < 15.0:
        return True
    time.sleep(0.25)
    return distance() < first - 0.5


def radio_works(rig: FaultRig, record: TickRecord) -> bool:
    """The radio follows Doppler: no radio fault, and the real rigctld is within 500 Hz (a few seconds of
    Doppler drift) of this tick's downlink frequency for the satellite's channel."""
    sample = rig.station.core.tracker.last_sample
    channel = rig.station.core.state.channels.get(ISS)
    if "rigctld" in record.faults or sample is None or sample.look_angles is None or channel is None:
        return False
    rx, _ = channel.ground_frequencies(sample.look_angles.range_rate_km_s)
    return abs(int(_ask(rig.rigctld.port, b"f\n")[0]) - rx) <= 500


def state_saved(rig: FaultRig, record: TickRecord) -> bool:
    return "state-file" not in record.faults and rig.state_path.is_file() and \
        f'"satellite": {rig.station.core.state.catalog_number}' in rig.state_path.read_text()


def config_kept(rig: FaultRig, record: TickRecord) -> bool:
    observer = rig.station.core.state.observer
    return "config" not in record.faults and observer is not None and abs(observer.latitude_deg - 52.2053) < 1e-6


# -- causes ---------------------------------------------------------------------------------------------
DECAYED = 99999  #: the catalog number the decay fault uses


def _decayed_set(rig: FaultRig, years_old: int) -> None:
    """ISS's elements as satellite 99999, with an epoch ``years_old`` years before ISS's: ten years old,
    SGP4 reports it decayed at every tick; a fresh set (0) computes again, as a refreshed set does."""
    iss = rig.station.core.state.catalog.get(ISS).elements
    year = int(iss.line1[18:20]) - years_old
    l1 = iss.line1[:2] + f"{DECAYED:05d}" + iss.line1[7:18] + f"{year:02d}" + iss.line1[20:68]
    l2 = iss.line2[:2] + f"{DECAYED:05d}" + iss.line2[7:68]
    sets = load_elements(f"DECAYED\n{l1}{tle_checksum(l1)}\n{l2}{tle_checksum(l2)}\n").sets
    core = rig.station.core
    core.state.catalog.update(sets)
    core.state.catalog_changed()
    if years_old:
        core.select_satellite(DECAYED, source="campaign")  # selected before it went bad (SAT= now refuses it)


def _state_dir_blocked(rig: FaultRig, blocked: bool) -> None:
    folder, away = rig.state_path.parent, rig.state_path.parent.with_name("state.away")
    if blocked:
        folder.rename(away)
        folder.write_text("a file where the state folder was\n")  # writes now fail with ENOTDIR
        rig.station.core.select_satellite(694, source="campaign")  # a change that must be saved
    else:
        folder.unlink()
        away.rename(folder)


def _stop_process(rig: FaultRig) -> None:
    """SIGSTOP for two minutes, then SIGCONT: the clock jumps with nobody ticking, every thread waiting on
    it wakes at once, and the scheduler may run the device workers before the publisher (forced here:
    the publisher is held until EasyComm's worker has had its period).  The satellite moved tens of
    degrees meanwhile."""
    easycomm = rig.station.easycomm
    assert easycomm is not None
    rig.station.publisher.stop()
    periods = easycomm.lines_written + getattr(easycomm, "stale_skipped", 0)
    rig.clock.advance(120.0)
    deadline = time.monotonic() + 2.0
    while easycomm.lines_written + getattr(easycomm, "stale_skipped", 0) == periods and time.monotonic() < deadline:
        time.sleep(0.001)
    ticks = rig.station.publisher.stats.ticks
    rig.station.publisher.start()  # its schedule starts again from now, with a tick at once
    while rig.station.publisher.stats.ticks == ticks and time.monotonic() < deadline + 2.0:
        time.sleep(0.001)


def _tcp_send(rig: FaultRig, data: bytes, replies: int) -> bytes:
    """Send ``data`` to the station's TCP port and read the greeting and ``replies`` lines after it."""
    assert rig.station.tcp is not None
    with socket.create_connection(rig.station.tcp.address, timeout=2.0) as s:
        s.sendall(data)
        got = b""
        while got.count(b"\r\n") < 1 + replies:
            chunk = s.recv(65536)
            if not chunk:
                break
            got += chunk
    return got


def _tcp_junk(rig: FaultRig) -> None:
    _tcp_send(rig, b"\x0b\r\n\x0c\r\n\x1c\x1d\x1e\x1f\r\n" * 50 + b"SUMMARY\r\n", 1)


def _nothing(rig: FaultRig) -> None:
    return None


def _slow_loris(rig: FaultRig) -> None:
    """Forty connections from 127.0.0.1, the address every local tool shares on the loopback default, opened
    at one instant, a byte each and never a line: over the per-address cap (32), so each of the last 8 closes
    the quietest before it (:mod:`nfwserver.tcp.admission`).  From then on a new connection from 127.0.0.1
    closes the quietest one again (:func:`tcp_served` makes one)."""
    tcp = rig.station.tcp
    assert tcp is not None
    rig.loris = LorisCounts(since=rig.clock.monotonic(), evicted_before=tcp.stats.evicted,
                            refused_before=tcp.stats.refused)
    for _ in range(40):
        s = socket.create_connection(tcp.address, timeout=2.0)
        s.sendall(b"S")
        rig.held_connections.append(s)


def _loris_gone(rig: FaultRig) -> None:
    tcp = rig.station.tcp
    if rig.loris is not None and tcp is not None:
        rig.loris.evicted = tcp.stats.evicted - rig.loris.evicted_before
        rig.loris.refused = tcp.stats.refused - rig.loris.refused_before
        rig.loris.since = None
    while rig.held_connections:
        rig.held_connections.pop().close()


def _served_status(rig: FaultRig, source: str) -> bool:
    """A client bound to ``source`` is greeted and answered ``STATUS``."""
    assert rig.station.tcp is not None
    with socket.socket() as s:
        s.bind((source, 0))
        s.settimeout(2.0)
        s.connect(rig.station.tcp.address)
        s.sendall(b"STATUS\r\n")
        data = b""
        while data.count(b"\r\n") < 2:
            chunk = s.recv(65536)
            if not chunk:
                return False
            data += chunk
    return data.startswith(b"Hello") and b"satellite=" in data


def tcp_served(rig: FaultRig, record: TickRecord) -> bool:
    """The feed publishes; every fifth tick a client from another address (127.0.0.2) is greeted and answered,
    and, while the slow-loris connections hold 127.0.0.1's cap, so is one from 127.0.0.1, as ``nfwserver
    status`` and ``poke`` connect: it needs the quietest connection closed to make room, and ``rig.loris``
    counts it."""
    if not record.published or rig.station.tcp is None or rig.index % 5:
        return record.published
    if not _served_status(rig, "127.0.0.2"):
        return False
    loris = rig.loris
    if loris is None or loris.since is None:
        return True
    if not _served_status(rig, "127.0.0.1"):
        return False
    loris.local_served += 1
    return True


def _still_target_then_kill(rig: FaultRig) -> None:
    """PARK to a still target (az 200, el 30: a geostationary satellite, or AO-10 near apogee, asks for no new
    target), once the rotor is on its way there, rotctld is killed; its restart (the fault's end) brings the
    dummy back at 0/0, its target forgotten.  Recovery is the rotor seen moving toward the target again."""
    rotor = rig.station.rotor
    assert rotor is not None
    rotor.driver.set_parking(0, 200, 30)
    rig.station.core.set_track(False, source="campaign")
    rotor.request_park()
    for _ in range(10):  # two seconds: the target sent, the dummy turning toward it
        rig.tick()
    rig.rotctld.kill()


_EDITS = {"elements.stale_days": "21", "tcp.idle_timeout_s": "299", "rotor.threshold_deg": "2.5",
          "radio.knob_tolerance_hz": "150", "server.ut1_utc_s": "0.0"}


def _concurrent_edits(rig: FaultRig) -> None:
    """Five ``config set`` runs on different keys of the station's own (watched) configuration, in parallel,
    and two ``elements update`` runs into one store, in parallel; what either lost is kept for ``works``."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    store = rig.work / "store.txt"
    store.unlink(missing_ok=True)
    sets = load_element_file(ELEMENTS).sets
    halves = [rig.work / "half-a.txt", rig.work / "half-b.txt"]
    halves[0].write_text("".join(es.tle_text() for es in sets[::2]))
    halves[1].write_text("".join(es.tle_text() for es in sets[1::2]))
    command = [sys.executable, "-m", "nfwserver"]
    procs = [subprocess.Popen([*command, "config", "set", "--config", str(rig.config_path), key, value], env=env,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) for key, value in _EDITS.items()]
    procs += [subprocess.Popen([*command, "elements", "update", str(half), "--store", str(store)], env=env,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) for half in halves]
    for proc in procs:
        proc.wait(120)
    written = parse_config(rig.config_path.read_text(), str(rig.config_path), rig.config_path.parent)
    values = {"elements.stale_days": written.elements.stale_days, "tcp.idle_timeout_s": written.tcp.idle_timeout_s,
              "rotor.threshold_deg": written.rotor.threshold_deg,
              "radio.knob_tolerance_hz": written.radio.knob_tolerance_hz, "server.ut1_utc_s": written.server.ut1_utc_s}
    rig.edits_lost = [key for key, value in _EDITS.items() if float(values[key]) != float(value)]
    stored = {es.catalog_number for es in load_element_file(store).sets} if store.exists() else set()
    missing = len({es.catalog_number for es in sets} - stored)
    if missing:
        rig.edits_lost.append(f"{missing} element sets")


def _edits_undone(rig: FaultRig) -> None:
    rig.config_path.write_text(rig.config_text)


def edits_kept(rig: FaultRig, record: TickRecord) -> bool:
    """Nothing the parallel edits wrote was lost, the feed publishes and the configuration is not refused."""
    return not rig.edits_lost and record.published and "config" not in record.faults


def _foreign_digits(rig: FaultRig) -> None:
    """Pokes with other scripts' digits (SAT=², ANTAZ=٣) over TCP and DDE: refused, nothing else changes."""
    _tcp_send(rig, "SAT=²\r\nANTAZ=٣\r\nSAT=２５５４４\r\n".encode(), 3)
    conv = rig.system.connect("NFW32", "NFW_DATA", client_name="digits")
    for text in ("SAT=²", "ANTEL=١"):
        try:
            conv.poke("NFW_SERVER", text)
        except Exception:  # refused (DDE_FNOTPROCESSED), as it must be
            pass
    conv.disconnect()


FAULTS = (
    Fault("rotctld refuses every move (RPRT -1)", "rotor",
          lambda rig: rig.rotor_proxy.set_mode("refuse"), lambda rig: rig.rotor_proxy.set_mode("pass"), rotor_works,
          real_time=True),
    Fault("rotor jammed: moves accepted, nothing turns", "rotor",
          lambda rig: rig.rotor_proxy.set_mode("jam"), lambda rig: rig.rotor_proxy.set_mode("pass"), rotor_works,
          duration_s=40.0, real_time=True),
    Fault("rotctld killed, restarted", "rotctld",
          lambda rig: rig.rotctld.kill(), lambda rig: rig.rotctld.restart(), rotor_works, real_time=True),
    Fault("rotctld restarted under a still target (recovered = the rotor seen moving)", "rotctld",
          _still_target_then_kill, lambda rig: rig.rotctld.restart(), rotor_moving, duration_s=8.0, real_time=True),
    Fault("rigctld killed, restarted", "rigctld",
          lambda rig: rig.rigctld.kill(), lambda rig: rig.rigctld.restart(), radio_works),
    Fault("rigctld answers one byte at a time", "rigctld",
          lambda rig: rig.radio_proxy.set_mode("trickle"), lambda rig: rig.radio_proxy.set_mode("pass"), radio_works,
          real_time=True),  # the reply deadline is real time: virtual seconds would not mean anything here
    Fault("EasyComm adapter unplugged, then plugged in again", "easycomm",
          lambda rig: rig.unplug_tty(), lambda rig: rig.plug_tty(), easycomm_works),
    Fault("selected set past decay (SGP4 error 6), then a fresh set", "tracking",
          lambda rig: _decayed_set(rig, 10), lambda rig: _decayed_set(rig, 0), feed_works, feed_may_stop=True),
    Fault("state folder unwritable, then writable", "state-file",
          lambda rig: _state_dir_blocked(rig, True), lambda rig: _state_dir_blocked(rig, False), state_saved),
    Fault("configuration file emptied by an editor mid-save, then written whole", "config",
          lambda rig: rig.config_path.write_text(""), lambda rig: rig.config_path.write_text(rig.config_text),
          config_kept),
    Fault("process stopped for 120 s (SIGSTOP/SIGCONT)", None, _stop_process, _nothing, feed_and_easycomm_current,
          duration_s=0.2),
    Fault("TCP lines of VT, FF and 0x1C-0x1F", None, _tcp_junk, _nothing, feed_works, duration_s=0.2),
    Fault("TCP slow-loris: 40 idle connections from 127.0.0.1; other addresses and local tools served", None,
          _slow_loris, _loris_gone, tcp_served, duration_s=10.0),
    Fault("pokes with other scripts' digits (SAT=², ANTAZ=٣) over TCP and DDE", None, _foreign_digits, _nothing,
          feed_works, duration_s=0.2),
    Fault("five config set and two elements update runs in parallel", None, _concurrent_edits, _edits_undone,
          edits_kept, duration_s=2.0),
)


def restore_baseline(rig: FaultRig) -> None:
    """Between faults: ISS selected again (a fault may have changed it); EasyComm lines written for the
    satellite selected before are drained and the stale-line count starts afresh (it belongs to one fault)."""
    if rig.station.core.state.catalog_number != ISS:
        rig.station.core.select_satellite(ISS, source="campaign")
        rig.tick()
    if not rig.station.core.state.snapshot().tracking:  # a fault parked the rotor
        rig.station.core.set_track(True, source="campaign")
        rig.tick()
    rig.drain_tty()
    rig.stale_easycomm = 0


