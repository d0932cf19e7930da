"""A real station for the fault campaign, stepped one tick at a time on a virtual clock.

:class:`FaultRig` builds ``nfwserver.app.station.Station`` from a configuration file (watched, so a
live reload can be faulted) with: the in-process DDE transport and a hot advise client, Nova's TCP
server on an ephemeral loopback port, a rotor on a real ``rotctld`` and a radio on a real ``rigctld``,
each behind a :class:`~tests.hamlib_fault_proxy.FaultProxy`, EasyComm on a pseudo-terminal,
the session state file in a work directory (removed at the end).  The clock starts during a high ISS pass.

:meth:`FaultRig.tick` advances the clock by one publish period, waits (real time, bounded) until the
publisher has ticked and the workers have had a moment, and returns a :class:`TickRecord`: what the
DDE client received for that tick, the STATUS line's fields as Nova's TCP protocol builds them, and
how many log records with a traceback were written since the previous tick.
"""

from __future__ import annotations

import logging
import os
import shutil
import socket
import tempfile
import time
from dataclasses import dataclass, field
from datetime import datetime, timedelta, timezone
from pathlib import Path

from nfwserver.app.station import Station
from nfwserver.clock import VirtualClock
from nfwserver.config.loader import parse_config
from nfwserver.fake_dde import FakeDdeSystem
from nfwserver.tcp.status_line import parse_status
from nfwserver.tracking.catalog import Catalog
from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.passes import find_passes
from tests.hamlib_daemons import HamlibDaemon
from tests.hamlib_fault_proxy import FaultProxy

ROOT = Path(__file__).resolve().parents[2]
ELEMENTS = ROOT / "tests" / "data" / "visual.txt"
OBSERVER = Observer(52.2053, 0.1218, 20.0)
ISS = 25544
RATE_HZ = 5.0


def iss_pass_start() -> datetime:
    """150 s before the culmination of the highest ISS pass over the observer on 2026-05-08 (from our own
    search; the campaign only needs *a* pass, not an accurate one): the faults that need the satellite up
    and moving (rotor, radio, EasyComm) come first."""
    catalog = Catalog(s for s in load_element_file(ELEMENTS).sets)
    day = datetime(2026, 5, 8, tzinfo=timezone.utc)
    best = max(find_passes([catalog.get(ISS)], OBSERVER, day, day + timedelta(days=1)),
               key=lambda p: p.max_elevation_deg)
    return best.tca - timedelta(seconds=150)


class TracebackCounter(logging.Handler):
    """Counts log records that carry exception information (a traceback in the log)."""

    def __init__(self) -> None:
        super().__init__(logging.DEBUG)
        self.count = 0
        self.last = ""

    def emit(self, record: logging.LogRecord) -> None:
        if record.exc_info:
            self.count += 1
            self.last = record.getMessage()


@dataclass
class TickRecord:
    """What one tick looked like from outside."""

    index: int
    time: datetime
    published: bool  #: the DDE advise client received a string for this tick
    text: str  #: the tick's Nova string ("" when none)
    status: dict[str, str]  #: STATUS fields
    tracebacks: int  #: log records with a traceback since the previous tick
    easycomm: list[str]  #: EasyComm lines written during this tick

    @property
    def faults(self) -> list[str]:
        value = self.status.get("faults", "none")
        return [] if value == "none" else value.split(",")


@dataclass
class LorisCounts:
    """What the slow-loris fault counted: the TCP server's refusals and evictions while it lasted, and how often
    a client from 127.0.0.1 (the operator's own tools' address) was served under the flood."""

    since: float | None  #: clock monotonic seconds the connections were opened; None once they are closed
    evicted_before: int
    refused_before: int
    evicted: int = 0  #: connections the server closed to make room (the quietest)
    refused: int = 0  #: connections refused with an ERROR line (over a cap, nobody to displace)
    local_served: int = 0  #: STATUS answered to a new client from 127.0.0.1


@dataclass
class FaultRig:
    """See the module docstring.  Use as a context manager."""

    work: Path = field(default_factory=lambda: Path(tempfile.mkdtemp(prefix="nfw-faults-")))

    def __post_init__(self) -> None:
        self.clock = VirtualClock(iss_pass_start())
        self.rotctld = HamlibDaemon("rotctld", extra=["--set-conf=min_az=0,max_az=450,min_el=0,max_el=90"]).start()
        self.rigctld = HamlibDaemon("rigctld").start()
        self.rotor_proxy = FaultProxy((self.rotctld.host, self.rotctld.port))
        self.radio_proxy = FaultProxy((self.rigctld.host, self.rigctld.port), trickle_s=0.3)
        self.tty = self.work / "ttyUSB0"  # a link to the pty, as udev makes for a USB adapter
        self.plug_tty()
        (self.work / "state").mkdir()
        self.state_path = self.work / "state" / "state.json"
        self.config_path = self.work / "nfwserver.toml"
        self.config_text = self._config_text()
        self.config_path.write_text(self.config_text)
        self.system = FakeDdeSystem()
        self.station = Station(parse_config(self.config_text), self.clock, transport=self.system.server_transport())
        self.tracebacks = TracebackCounter()
        logging.getLogger().addHandler(self.tracebacks)
        self._seen_tracebacks = 0
        self.received: list[tuple[int, str]] = []  # (tick index, text) of every DDE delivery
        self.index = 0
        self.stale_easycomm = 0  #: EasyComm lines more than 5 deg from the tick that was current when read
        #: pace ticks at real time (the real rotctld turns its dummy rotor in real time: rotor faults need it)
        self.real_time = False
        self.rotor_distance = float("inf")  #: last seen distance (deg) of the real rotor from its target
        self.held_connections: list[socket.socket] = []  #: the slow-loris fault's open connections
        self.loris: LorisCounts | None = None  #: what the last slow-loris fault counted
        self.edits_lost: list[str] = []  #: what the concurrent-edits fault lost (settings, element sets)
        self._last_tick = time.monotonic()

    def _config_text(self) -> str:
        return (
            f'[observer]\nlocation = "{OBSERVER.latitude_deg},{OBSERVER.longitude_deg},{OBSERVER.altitude_m}"\n'
            f'[elements]\nfiles = ["{ELEMENTS}"]\nuse_bundled = false\nstore = "none"\n'
            f'[server]\nstate_file = "{self.state_path}"\nsatellite = {ISS}\ntune = true\ntrack = true\n'
            f'rate_hz = {RATE_HZ:g}\n'
            '[tcp]\nenabled = true\nport = 0\nallow = ["127.0.0.0/8"]\n'
            f'[rotor]\nbackend = "rotctld"\nport = {self.rotor_proxy.port}\ngeometry = "overlap-450"\n'
            f'[radio]\nenabled = true\nbackend = "rigctld"\nport = {self.radio_proxy.port}\n'
            f'[easycomm]\nenabled = true\ndevice = "{self.tty}"\n')

    # -- life cycle ------------------------------------------------------------------------------------
    def __enter__(self) -> FaultRig:
        self.station.start()
        self.station.watch_config(str(self.config_path), interval_s=1.0)
        conv = self.system.connect("NFW32", "NFW_DATA", client_name="campaign")
        conv.on_receive = lambda r: self.received.append((self.index, r.text or ""))
        conv.start_advise("NFW_SERVER", hot=True)
        self.conv = conv
        return self

    def __exit__(self, *exc: object) -> None:
        self.station.stop()
        shutil.rmtree(self.work, ignore_errors=True)
        logging.getLogger().removeHandler(self.tracebacks)
        for proxy in (self.rotor_proxy, self.radio_proxy):
            proxy.close()
        for daemon in (self.rotctld, self.rigctld):
            daemon.kill()
        if self.master >= 0:
            os.close(self.master)
            os.close(self._slave)

    def plug_tty(self) -> None:
        """A new pseudo-terminal behind the adapter's name (plugged in)."""
        self.master, self._slave = os.openpty()
        self.tty.unlink(missing_ok=True)
        self.tty.symlink_to(os.ttyname(self._slave))

    def unplug_tty(self) -> None:
        """The adapter pulled out: the terminal and its name are gone."""
        if self.master >= 0:
            os.close(self.master)
            os.close(self._slave)
        self.master = self._slave = -1
        self.tty.unlink()

    # -- stepping --------------------------------------------------------------------------------------
    def drain_tty(self) -> bytes:
        """Whatever EasyComm wrote since the last call (non-blocking)."""
        if self.master < 0:
            return b""
        os.set_blocking(self.master, False)
        data = b""
        try:
            while chunk := os.read(self.master, 65536):
                data += chunk
        except (BlockingIOError, OSError):
            pass
        return data

    def tick(self) -> TickRecord:
        """One publish period of virtual time; see the module docstring."""
        if self.real_time:
            time.sleep(max(0.0, self._last_tick + 1.0 / RATE_HZ - time.monotonic()))
        self._last_tick = time.monotonic()
        publisher = self.station.publisher
        before = publisher.stats.ticks
        self.index += 1
        # A microsecond past the slot: the publisher's t0 + k / rate may round one ulp above k steps of 1 / rate.
        self.clock.advance(1.0 / RATE_HZ + 1e-6)
        deadline = time.monotonic() + 2.0
        while publisher.stats.ticks == before and time.monotonic() < deadline:
            time.sleep(0.0005)
        sample = self.station.core.tracker.last_sample
        # Judge the devices once their workers have handled this tick (bounded: a worker held by a fault
        # is judged as it is then).
        workers = [w for w in (self.station.rotor, self.station.radio) if w is not None]
        until = time.monotonic() + 0.3
        while sample is not None and time.monotonic() < until and any(
                w.processed_time is None or w.processed_time < sample.time for w in workers):
            time.sleep(0.0005)
        time.sleep(0.002)
        text = sample.text if sample is not None else ""
        got = any(i == self.index and t for i, t in self.received[-3:])
        assert self.station.tcp is not None
        status = parse_status(self.station.tcp.protocol.status_line())
        traces, self._seen_tracebacks = self.tracebacks.count - self._seen_tracebacks, self.tracebacks.count
        lines = [line for line in self.drain_tty().decode("ascii", "replace").split("\r\n") if line]
        la = sample.look_angles if sample is not None else None
        for line in lines:
            if line.startswith("AZ") and la is not None:
                az, el = float(line[2:].split()[0]), float(line.split()[1][2:])
                daz = abs((az - la.azimuth_deg + 180.0) % 360.0 - 180.0)
                if daz > 5.0 or abs(el - la.elevation_deg) > 5.0:
                    self.stale_easycomm += 1
        return TickRecord(self.index, self.clock.now(), got, text, status, traces, lines)

    def run(self, seconds: float) -> list[TickRecord]:
        return [self.tick() for _ in range(round(seconds * RATE_HZ))]
