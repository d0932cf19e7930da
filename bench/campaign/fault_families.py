"""The fault families: hostile Hamlib replies from a scripted loopback peer, and the real rotctld/rigctld
killed and restarted under a running station.

A corrupt value taken for a good one (a non-finite position or one outside the rotor's range, a frequency
outside 100 kHz..300 GHz) counts as data lost; an exception other than the backends' own
``RotorError``/``RadioError`` escaping a backend call, or any exception escaping the KCT driver or the
Doppler tuner (which must absorb device faults), counts as a crash.
"""

from __future__ import annotations

import math
import random
import threading
import time

from bench.campaign.station_rig import StationRig
from bench.campaign.tally import Tally
from nfwserver.channels.channel import Channel
from nfwserver.clock import SystemClock
from nfwserver.radio.backend import RadioError
from nfwserver.radio.rigctld_backend import RigctldBackend
from nfwserver.radio.tuning import DopplerTuner
from nfwserver.rotor.backend import RotorError
from nfwserver.rotor.geometry import RotorGeometry
from nfwserver.rotor.kct_driver import KctDriver
from nfwserver.rotor.kct_status import KctStatusBit
from nfwserver.rotor.rotctld_backend import RotctldBackend
from tests.hamlib_peer import ScriptedPeer

GEOMETRY = RotorGeometry(0.0, 450.0, 0.0, 90.0)
BAD_NUMBERS = ("nan", "inf", "-inf", "1e308", "-1e308", "1e999", "", "x", "0x10", "-0", "99999999999999999999", "NaN",
               "12,5", " 7 ", "\x00", "1e-320")


class HostilePeer:
    """A loopback TCP server speaking Hamlib's line protocol: each command gets a reply drawn (seeded) from
    valid answers and hostile ones -- garbage, non-finite or huge values, RPRT junk, a value where RPRT is
    due and the reverse, 100 KB to 1 MB without a newline, silence, or the connection closed."""

    def __init__(self, seed: int) -> None:
        self.rng = random.Random(seed)
        self._lock = threading.Lock()
        self.peer = ScriptedPeer(lambda command, _n: self.answer(command))
        self.port = self.peer.port

    def answer(self, command: str) -> bytes | None:
        """Bytes to send for ``command``; b"" sends nothing, None closes the connection."""
        with self._lock:
            rng = self.rng
            pick = rng.random()
            word = command.strip().split(" ")[0].lstrip("+\\")
            getter = word in ("p", "get_pos", "f", "get_freq", "i", "get_split_freq", "m", "get_mode")
            if pick < 0.4:  # valid
                if word in ("p", "get_pos"):
                    return f"{rng.uniform(0, 450):.6f}\n{rng.uniform(0, 90):.6f}\n".encode()
                if getter:
                    return f"{rng.randint(100_000, 3_000_000_000)}\n".encode()
                return b"RPRT 0\n"
            if pick < 0.6:
                values = "\n".join(rng.choice(BAD_NUMBERS) for _ in range(2 if word in ("p", "get_pos") else 1))
                return values.encode("utf-8", "replace") + b"\n"
            if pick < 0.7:
                return rng.choice((b"RPRT banana\n", b"RPRT -1\n", b"RPRT 0\n", b"RPRT -11\n", b"RPRT\n",
                                   b"145800000\n", b"RPRT 0\nRPRT 0\n"))
            if pick < 0.8:
                return bytes(rng.getrandbits(8) for _ in range(rng.randint(1, 300)))
            if pick < 0.85:
                return b"9" * rng.choice((70_000, 100_000, 1_000_000))
            if pick < 0.93:
                return rng.choice((b"14580", b"12.5", b"RPRT"))  # cut short
            if pick < 0.97:
                return b""  # silence: the client must time out
            return None

    def close(self) -> None:
        self.peer.close()


def _position_ok(position: tuple[float, float] | None) -> bool:
    if position is None:
        return True
    az, el = position
    return (math.isfinite(az) and math.isfinite(el) and GEOMETRY.az_min - 5 <= az <= GEOMETRY.az_max + 5
            and GEOMETRY.el_min - 5 <= el <= GEOMETRY.el_max + 5)


def _frequency_ok(hz: int | None) -> bool:
    return hz is None or (isinstance(hz, int) and 100_000 <= hz <= 300_000_000_000)


def run_hostile_hamlib(tally: Tally, count: int, seed: int) -> None:
    """``count`` device calls in all, spread over the rotor and radio backends and the driver and tuner."""
    peer = HostilePeer(seed)
    clock = SystemClock()
    rotor = RotctldBackend(clock, GEOMETRY, port=peer.port, timeout_s=0.2)
    radio = RigctldBackend(clock, port=peer.port, timeout_s=0.2)
    driver = KctDriver(clock, RotctldBackend(clock, GEOMETRY, port=peer.port, timeout_s=0.2), GEOMETRY)
    tuner = DopplerTuner(Channel("campaign", 437_800_000, 145_990_000),
                         RigctldBackend(clock, port=peer.port, timeout_s=0.2), clock=clock)
    refused = 0
    rng = random.Random(seed + 3)
    try:
        for k in range(count):
            tally.tried += 1
            step = k % 6
            try:
                if step == 0:
                    position = rotor.get_position()
                    if not _position_ok(position):
                        tally.loss(f"rotctld position {position} accepted")
                elif step == 1:
                    rotor.set_position(rng.uniform(0, 450), rng.uniform(0, 90))
                elif step == 2:
                    hz = radio.get_rx_frequency()
                    if not _frequency_ok(hz):
                        tally.loss(f"rigctld frequency {hz!r} accepted")
                elif step == 3:
                    radio.set_rx_frequency(rng.randint(144_000_000, 146_000_000))
            except (RotorError, RadioError):
                refused += 1
            except Exception as exc:
                tally.crash(f"backend call {step}", exc)
            try:  # the driver and the tuner absorb device faults: nothing may escape them
                if step == 4:
                    elevation = rng.uniform(0, 90)  # drawn first, as before
                    driver.set_target(azimuth_deg=rng.uniform(0, 360), elevation_deg=elevation)
                    driver.service()
                    driver.status()
                    if not _position_ok(driver.rotor_position()):
                        tally.loss(f"driver position {driver.rotor_position()} accepted")
                elif step == 5:
                    tuner.update(rng.uniform(-7.5, 7.5))
            except Exception as exc:
                tally.crash(f"{'KctDriver' if step == 4 else 'DopplerTuner'} raised", exc)
    finally:
        for backend in (rotor, radio):
            backend.close()
        peer.close()
    tally.extra.update({"refused as device errors": refused,
                        "faults counted by the connections": rotor.connection.faults + radio.connection.faults})


def run_daemon_kills(tally: Tally, rig: StationRig, kills: int) -> None:
    """Kill rotctld and rigctld together ``kills`` times under the running station; each time, the rotor
    and the radio must come back within 5 s of the daemons' return, and the station keep publishing."""
    if rig.rot is None or rig.rig is None:
        tally.note("skipped: rotctld/rigctld not installed")
        return
    station = rig.station
    delays = []
    seen_down = 0
    for _ in range(kills):
        tally.tried += 1
        rig.rot.kill()
        rig.rig.kill()
        gone_at = time.monotonic()  # both must be seen gone before they return, or "back" means nothing
        while time.monotonic() - gone_at < 3.0:
            if station.rotor.driver.status().bits & KctStatusBit.CARD_ABSENT and not station.radio.tuner.available:
                seen_down += 1
                break
            time.sleep(0.02)
        rig.rot.start()
        rig.rig.start()
        back_at = time.monotonic()
        while True:
            rotor_up = not station.rotor.driver.status().bits & KctStatusBit.CARD_ABSENT
            radio_up = station.radio.tuner.available
            if rotor_up and radio_up:
                delays.append(time.monotonic() - back_at)
                break
            if time.monotonic() - back_at > 5.0:
                tally.loss(f"rotor {'up' if rotor_up else 'down'}, radio {'up' if radio_up else 'down'} "
                           "5 s after the daemons returned")
                break
            time.sleep(0.02)
        rig.check(tally, settle_s=0.2)
    stats = station.publisher.stats
    tally.extra.update({"outages seen by rotor and radio": seen_down,
                        "back after (max)": f"{max(delays):.2f} s" if delays else "-",
                        "publish ticks late by more than 0.25 s": stats.lateness.over(0.25)})
