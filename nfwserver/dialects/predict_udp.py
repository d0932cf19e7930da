"""PREDICT's UDP socket server (default port 1210), answering from our session.

Request and reply formats follow PREDICT 2.2's ``socket_server`` (KD2BD) byte for byte: one
datagram per request, a command word optionally followed by a blank and a satellite name or catalog
number; replies are newline-separated fields written with C ``printf`` formats:

- ``GET_SAT name``: name, sub-satellite longitude (degrees *west*, ``%-7.2f``), latitude
  (``%+-6.2f``), azimuth, elevation, next AOS/LOS as Unix time (``%ld``), footprint diameter (km),
  range (km), altitude (km), speed (km/s), orbit number, visibility (``V`` visible, ``D`` daylight,
  ``N`` not visible), phase (0-256), eclipse depth (deg), squint (deg; 360 when unknown);
- ``GET_DOPPLER name``: Doppler shift at 100 MHz (``%f``);
- ``GET_TLE name``: name and the two element lines;
- ``GET_LIST``: the tracked satellites' names, one per line (PREDICT always lists 24 slots);
- ``GET_SUN`` / ``GET_MOON``: azimuth, elevation, declination, Greenwich hour angle, right ascension;
- ``GET_QTH``: callsign, latitude, longitude (*west* positive) (``%g``), altitude in metres (``%d``);
- ``GET_TIME``: Unix time (``%lu``); ``GET_TIME$``: ``asctime`` text with the day zero-padded;
- ``GET_VERSION``, ``GET_MODE``, ``RELOAD_TLE`` (empty reply); anything else: ``Huh?``.

The server binds 127.0.0.1 unless told otherwise; a malformed datagram gets ``Huh?`` and never stops it.
"""

from __future__ import annotations

import logging
import socket
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from datetime import datetime, timedelta, timezone

from nfwserver import __version__
from nfwserver.clock import Clock
from nfwserver.core.state import StationState
from nfwserver.tracking.bodies import BodyView, moon_view, sun_view
from nfwserver.tracking.catalog import Catalog, Satellite
from nfwserver.tracking.constants import SPEED_OF_LIGHT_KM_S
from nfwserver.tracking.derived import satellite_report
from nfwserver.tracking.look_angles import LookAngleCalculator, PropagationError
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.passes import find_passes

log = logging.getLogger(__name__)
DEFAULT_PORT = 1210


@dataclass
class PredictContext:
    """What the PREDICT protocol reports about: the live station state (never a copy) and its satellites."""

    state: StationState
    clock: Clock
    tracked: Callable[[], list[int]]  #: catalog numbers listed by GET_LIST (at most 24)
    mode: Callable[[], str] = lambda: "none"
    callsign: str = "NFWSERVER"
    on_reload: Callable[[], None] | None = None
    #: next AOS/LOS per satellite: (observer it was computed for, computed at, event)
    _next_event: dict[int, tuple[object, datetime, datetime]] = field(default_factory=dict)

    def catalog(self) -> Catalog:
        return self.state.catalog

    @property
    def observer(self) -> Observer:
        observer = self.state.observer
        if observer is None:
            raise ValueError("no station location is configured")
        return observer

    @property
    def ut1_utc(self) -> float:
        return self.state.ut1_utc_s


def _find(catalog: Catalog, text: str) -> Satellite | None:
    text = text.strip()[:25]
    if text.isdigit():
        return catalog.get(int(text))
    for sat in catalog:
        if sat.name[:25] == text or sat.dde_name == text:
            return sat
    return None


def _c_float(value: float, spec: str) -> str:
    """printf-style float formatting for the specs PREDICT uses (%-7.2f, %+-6.2f, %f)."""
    if spec == "%-7.2f":
        return f"{value:<7.2f}"
    if spec == "%+-6.2f":
        return f"{value:<+6.2f}"
    return f"{value:f}"


class PredictProtocol:
    """Turns one request datagram into its reply (no I/O: the server and the tests use it)."""

    def __init__(self, context: PredictContext) -> None:
        self.ctx = context

    def reply(self, datagram: bytes) -> bytes:
        try:
            text = datagram.split(b"\x00", 1)[0].decode("ascii", errors="replace")
            return self._reply(text).encode("ascii", errors="replace")
        except Exception:  # a bad request must never stop the server
            log.exception("PREDICT request failed")
            return b"Huh?\n"

    def _argument(self, text: str) -> str:
        head, _, rest = text.partition(" ")
        return rest.split("\n", 1)[0]

    def _reply(self, text: str) -> str:
        now = self.ctx.clock.now()
        if text.startswith("GET_SAT") and not text.startswith("GET_SAT_POS"):
            sat = _find(self.ctx.catalog(), self._argument(text))
            return self._get_sat(sat, now) if sat else "Huh?\n"
        if text.startswith("GET_TLE"):
            sat = _find(self.ctx.catalog(), self._argument(text))
            return f"{sat.name}\n{sat.elements.line1}\n{sat.elements.line2}\n" if sat else "Huh?\n"
        if text.startswith("GET_DOPPLER"):
            sat = _find(self.ctx.catalog(), self._argument(text))
            if sat is None:
                return "Huh?\n"
            la = LookAngleCalculator(self.ctx.observer, self.ctx.ut1_utc).compute(sat.satrec, now)
            return _c_float(-100e6 * la.range_rate_km_s / SPEED_OF_LIGHT_KM_S, "%f") + "\n"
        if text.startswith("GET_LIST"):
            catalog = self.ctx.catalog()
            names = [catalog.get(n).name for n in self.ctx.tracked()[:24] if catalog.get(n) is not None]
            return "".join(f"{name}\n" for name in names + [""] * (24 - len(names)))
        if text.startswith("RELOAD_TLE"):
            if self.ctx.on_reload is not None:
                self.ctx.on_reload()
            return ""
        if text.startswith("GET_SUN"):
            return self._body(sun_view(self.ctx.observer, now, self.ctx.ut1_utc))
        if text.startswith("GET_MOON"):
            return self._body(moon_view(self.ctx.observer, now, self.ctx.ut1_utc))
        if text.startswith("GET_MODE"):
            return self.ctx.mode()
        if text.startswith("GET_VERSION"):
            return f"{__version__}\n"
        if text.startswith("GET_QTH"):
            o = self.ctx.observer
            west = -o.longitude_deg % 360.0
            return f"{self.ctx.callsign}\n{o.latitude_deg:g}\n{west:g}\n{int(round(o.altitude_m))}\n"
        if text.startswith("GET_TIME$"):
            stamp = time.asctime(now.astimezone(timezone.utc).timetuple()) + "\n"
            return stamp[:8] + "0" + stamp[9:] if stamp[8] == " " else stamp
        if text.startswith("GET_TIME"):
            return f"{int(now.timestamp())}\n"
        return "Huh?\n"

    @staticmethod
    def _body(view: BodyView) -> str:
        """az, el, declination, GHA, RA of the Sun or the Moon."""
        return (f"{_c_float(view.azimuth_deg, '%-7.2f')}\n{_c_float(view.elevation_deg, '%+-6.2f')}\n"
                f"{_c_float(view.declination_deg, '%-7.2f')}\n{_c_float(view.greenwich_hour_angle_deg, '%-7.2f')}\n"
                f"{_c_float(view.right_ascension_deg, '%-7.2f')}\n")

    def _next_event(self, sat: Satellite, now: datetime, up: bool) -> datetime | None:
        cached = self.ctx._next_event.get(sat.catalog_number)
        if cached is None or cached[0] != self.ctx.observer or not (cached[1] <= now < cached[2]):
            passes = find_passes([sat], self.ctx.observer, now, now + timedelta(days=2), ut1_utc=self.ctx.ut1_utc)
            events = sorted(t for p in passes for t in (p.aos, p.los) if t is not None and t > now)
            if not events:
                return None
            self.ctx._next_event[sat.catalog_number] = (self.ctx.observer, now, events[0])
            return events[0]
        return cached[2]

    def _get_sat(self, sat: Satellite, now: datetime) -> str:
        try:
            rep = satellite_report(sat.elements, self.ctx.observer, now, self.ctx.ut1_utc)
        except PropagationError:
            return "Huh?\n"
        west = -rep.longitude_deg % 360.0
        event = self._next_event(sat, now, rep.elevation_deg >= 0.0)
        next_event = int(event.timestamp()) if event is not None else 0
        eclipse_depth = 0.0 if rep.sunlit else -1.0
        return (f"{sat.name}\n{_c_float(west, '%-7.2f')}\n{_c_float(rep.latitude_deg, '%+-6.2f')}\n"
                f"{_c_float(rep.azimuth_deg, '%-7.2f')}\n{_c_float(rep.elevation_deg, '%+-6.2f')}\n{next_event}\n"
                f"{_c_float(rep.footprint_km, '%-7.2f')}\n{_c_float(rep.range_km, '%-7.2f')}\n"
                f"{_c_float(rep.height_km, '%-7.2f')}\n{_c_float(rep.speed_km_s, '%-7.2f')}\n{rep.rev}\n"
                f"{rep.visibility}\n{_c_float(rep.phase, '%-7.2f')}\n"
                f"{_c_float(eclipse_depth, '%-7.2f')}\n{_c_float(360.0, '%-7.2f')}\n")


class PredictUdpServer:
    """The UDP listener on its own thread (``nfw-predict``).  Construction does no I/O; :meth:`start`
    binds the socket (raising :class:`OSError` when the port is taken) and starts the thread."""

    def __init__(self, context: PredictContext, host: str = "127.0.0.1", port: int = DEFAULT_PORT) -> None:
        self.protocol = PredictProtocol(context)
        self.host, self.port = host, port
        self.sock: socket.socket | None = None
        self.address: tuple[str, int] = (host, port)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="nfw-predict", daemon=True)

    def start(self) -> None:
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            sock.bind((self.host, self.port))
        except OSError:
            sock.close()
            raise
        sock.settimeout(0.2)
        self.sock = sock
        self.address = sock.getsockname()
        log.info("PREDICT protocol on UDP %s:%d", *self.address)
        self._thread.start()

    def _run(self) -> None:
        sock = self.sock
        assert sock is not None
        while not self._stop.is_set():
            try:
                data, peer = sock.recvfrom(2048)
            except TimeoutError:
                continue
            except OSError:
                if self._stop.is_set():
                    return
                continue
            try:
                sock.sendto(self.protocol.reply(data), peer)
            except OSError as exc:
                log.warning("PREDICT reply to %s failed: %s", peer, exc)

    def stop(self) -> None:
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(2.0)
        if self.sock is not None:
            self.sock.close()
