"""PREDICT 2.2's UDP request/reply protocol (KD2BD's ``socket_server`` in predict.c), without sockets.

A request is one datagram of at most 80 bytes (PREDICT's buffer; the rest is dropped), read up to its
first NUL: a command word, optionally a blank and an argument that ends at a LF, a NUL or the end of the
datagram (all equivalent; a CR stays part of it, as in PREDICT).  Commands are matched by prefix in
PREDICT's order: ``GET_SAT`` (not ``GET_SAT_POS``), ``GET_TLE``, ``GET_DOPPLER``, ``GET_LIST``,
``RELOAD_TLE``, ``GET_SUN``, ``GET_MOON``, ``GET_MODE``, ``GET_VERSION``, ``GET_QTH``, ``GET_TIME$``,
``GET_TIME``, ``GET_SAT_POS``, ``PREDICT``; anything else gets ``Huh?``.  Replies use PREDICT's C
``printf`` formats:

- ``GET_SAT name``: name, sub-satellite longitude (degrees *west*, ``%-7.2f``), latitude
  (``%+-6.2f``), azimuth, elevation, next AOS/LOS as Unix time (``%ld``), footprint diameter (km),
  range (km), altitude (km), speed (km/s), orbit number, visibility (``V`` visible, ``D`` daylight,
  ``N`` not visible), phase (0-256), eclipse depth (deg), squint (deg; 360 when unknown);
- ``GET_DOPPLER name``: Doppler shift at 100 MHz (``%f``);  ``GET_TLE name``: name and the two lines;
- ``GET_LIST``: the listed satellites' names, one per line (always 24 lines);
- ``GET_SUN`` / ``GET_MOON``: azimuth, elevation, declination, Greenwich hour angle, right ascension;
- ``GET_QTH``: callsign, latitude, longitude (*west* positive) (``%g``), altitude in metres (``%d``);
- ``GET_TIME``: Unix time (``%lu``); ``GET_TIME$``: ``asctime`` text with the day zero-padded;
- ``GET_VERSION``; ``GET_MODE``: empty before anything was tracked, the tracked satellite's name and a LF
  while one is, ``NONE`` and a LF after tracking stopped; ``RELOAD_TLE``: an empty datagram;
- ``GET_SAT_POS name start [end]`` and ``PREDICT name start``: ``predict -f``/``-p`` lines
  (:mod:`nfwserver.dialects.predict_listing`), one datagram each, then the two bytes ``0x1A 0x0A``.

Satellites are found as PREDICT does: the name compared over 25 characters (``GET_SAT``, ``GET_TLE``,
``GET_DOPPLER``) or whole (listings), or the argument's leading number (C ``atol``) as catalog number;
we also accept the DDE name and search the whole catalog, not only the 24 listed.  A satellite that is
not found, cannot be propagated, or a station without a location answers ``Huh?`` (listings: only the
terminator).  Names are written with control and non-ASCII characters as ``?``, so fields never shift.
"""

from __future__ import annotations

import logging
import shlex
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from datetime import datetime, timedelta, timezone

from nfwserver.clock import Clock
from nfwserver.core.state import StationState
from nfwserver.dialects.predict_listing import Listing, atol
from nfwserver.ratelimited_log import RateLimitedLog
from nfwserver.release import package_version
from nfwserver.tracking.bodies import BodyView, moon_view, sun_view
from nfwserver.tracking.catalog import Catalog, Satellite
from nfwserver.tracking.constants import SPEED_OF_LIGHT_KM_S
from nfwserver.tracking.derived import satellite_report
from nfwserver.tracking.look_angles import LookAngleCalculator, PropagationError
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.passes import find_passes

log = logging.getLogger(__name__)
REQUEST_BYTES = 80  #: PREDICT's receive buffer
HUH = b"Huh?\n"
END_OF_LISTING = b"\x1a\n"  #: Control-Z and LF, PREDICT's end-of-file marker
LISTING_COMMANDS = ("GET_SAT_POS", "PREDICT")


@dataclass
class PredictContext:
    """What the PREDICT protocol reports about: the live station state (never a copy) and its satellites."""

    state: StationState
    clock: Clock
    tracked: Callable[[], list[int]]  #: catalog numbers listed by GET_LIST (at most 24)
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
            raise NoLocation("no station location is configured")
        return observer

    @property
    def ut1_utc(self) -> float:
        return self.state.ut1_utc_s


class NoLocation(ValueError):
    """The station has no location, so nothing can be computed."""


def safe_field(text: str) -> str:
    """``text`` with control characters (and anything not ASCII) as ``?``: one reply field, one line."""
    return "".join(c if " " <= c < "\x7f" else "?" for c in text)


def command_text(datagram: bytes) -> str:
    """The request as PREDICT sees it: the first 80 bytes up to the first NUL (bytes over 127 as ``?``)."""
    return datagram[:REQUEST_BYTES].split(b"\x00", 1)[0].decode("ascii", errors="replace")


def argument(text: str, limit: int) -> str:
    """PREDICT's argument parse: after the first blank (searched over 39 characters), up to a LF, at most
    ``limit`` characters; empty when the command has no blank."""
    i = 0
    while i < 39 and i < len(text) and text[i] != " ":
        i += 1
    if i >= len(text):
        return ""
    return text[i + 1:].split("\n", 1)[0][:limit]


def find_satellite(catalog: Catalog, name: str, compare: int | None = 25) -> Satellite | None:
    """By name (first ``compare`` characters; whole when None), DDE name, then catalog number (C ``atol``)."""
    if not name:
        return None
    for sat in catalog:
        if (sat.name[:compare] if compare else sat.name) == name or sat.dde_name == name:
            return sat
    number = atol(name)
    return catalog.get(number) if number > 0 else None


def _c_float(value: float, spec: str) -> str:
    """printf-style float formatting for the specs PREDICT uses (%-7.2f, %+-6.2f, %f)."""
    if spec == "%-7.2f":
        return f"{value:<7.2f}"
    if spec == "%+-6.2f":
        return f"{value:<+6.2f}"
    return f"{value:f}"


class PredictProtocol:
    """Turns one request datagram into its reply datagrams (no I/O: the server and the tests use it)."""

    def __init__(self, context: PredictContext) -> None:
        self.ctx = context
        self.diagnostics = RateLimitedLog(log, context.clock)
        self._tracked_once = False

    @staticmethod
    def is_listing(datagram: bytes) -> bool:
        """True for ``GET_SAT_POS``/``PREDICT``, whose answers can be long (the server runs them apart)."""
        return command_text(datagram).startswith(LISTING_COMMANDS)

    def reply(self, datagram: bytes) -> bytes:
        """The one datagram answering a request that is not a listing."""
        try:
            return self._reply(command_text(datagram)).encode("ascii", errors="replace")
        except NoLocation as exc:
            self.diagnostics.warning("no-location", "PREDICT request %r not answered: %s", datagram[:40], exc)
        except Exception as exc:  # a bad request must never stop the server, nor flood the log
            log.debug("PREDICT request %r failed", datagram[:40], exc_info=True)
            self.diagnostics.warning("failed", "PREDICT request %r failed: %s: %s", datagram[:40],
                                     type(exc).__name__, exc)
        return HUH

    def listing(self, datagram: bytes) -> Iterator[bytes]:
        """The datagrams answering ``GET_SAT_POS``/``PREDICT``: one per line, then ``0x1A 0x0A``."""
        text = command_text(datagram)
        try:
            self._note_tracking()
            words = self._words(argument(text, 49))
            now = int(self.ctx.clock.now().timestamp())
            sat = find_satellite(self.ctx.catalog(), words[0], None) if words else None
            if sat is not None:
                listing = Listing(sat.elements, self.ctx.observer, self.ctx.ut1_utc)
                lines = listing.find(now, *(words[1:3] + ["", ""])[:2]) if text.startswith("GET_SAT_POS") \
                    else listing.predict(now, (words[1:2] + [""])[0])
                for line in lines:
                    yield line.encode("ascii", errors="replace")
        except NoLocation as exc:
            self.diagnostics.warning("no-location", "PREDICT request %r not answered: %s", datagram[:40], exc)
        except Exception as exc:
            log.debug("PREDICT listing %r failed", datagram[:40], exc_info=True)
            self.diagnostics.warning("failed", "PREDICT request %r failed: %s: %s", datagram[:40],
                                     type(exc).__name__, exc)
        yield END_OF_LISTING

    @staticmethod
    def _words(text: str) -> list[str]:
        """The arguments ``predict -f``/``-p`` receive from PREDICT's shell command line: words (quotes
        honoured), up to the first that starts with ``-`` (an option to PREDICT)."""
        try:
            lexer = shlex.shlex(text, posix=True)
            lexer.whitespace_split, lexer.commenters = True, ""
            words = list(lexer)
        except ValueError:
            words = text.split()
        taken: list[str] = []
        for word in words:
            if not word or word.startswith("-"):
                break
            taken.append(word)
        return taken

    def _reply(self, text: str) -> str:
        self._note_tracking()
        now = self.ctx.clock.now()
        if text.startswith("GET_SAT") and not text.startswith("GET_SAT_POS"):
            sat = find_satellite(self.ctx.catalog(), argument(text, 25))
            return self._get_sat(sat, now) if sat else "Huh?\n"
        if text.startswith("GET_TLE"):
            sat = find_satellite(self.ctx.catalog(), argument(text, 25))
            return f"{safe_field(sat.name)}\n{sat.elements.line1}\n{sat.elements.line2}\n" if sat else "Huh?\n"
        if text.startswith("GET_DOPPLER"):
            sat = find_satellite(self.ctx.catalog(), argument(text, 25))
            return self._doppler(sat, now) if sat else "Huh?\n"
        if text.startswith("GET_LIST"):
            catalog = self.ctx.catalog()
            sats = [catalog.get(n) for n in self.ctx.tracked()[:24]]
            names = [safe_field(s.name) for s in sats if s is not None]
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
            return self._mode()
        if text.startswith("GET_VERSION"):
            return f"{package_version()}\n"
        if text.startswith("GET_QTH"):
            o = self.ctx.observer
            west = -o.longitude_deg % 360.0
            return f"{safe_field(self.ctx.callsign)}\n{o.latitude_deg:g}\n{west:g}\n{int(round(o.altitude_m))}\n"
        if text.startswith("GET_TIME$"):
            stamp = time.asctime(now.astimezone(timezone.utc).timetuple()) + "\n"
            return stamp[:8] + "0" + stamp[9:] if stamp[8] == " " else stamp
        if text.startswith("GET_TIME"):
            return f"{int(now.timestamp())}\n"
        return "Huh?\n"

    def _tracking_now(self) -> Satellite | None:
        snap = self.ctx.state.snapshot()
        return snap.satellite if snap.satellite is not None and (snap.feed_on or snap.tracking) else None

    def _note_tracking(self) -> None:
        if not self._tracked_once and self._tracking_now() is not None:
            self._tracked_once = True

    def _mode(self) -> str:
        """PREDICT's ``tracking_mode``: "" until something is tracked, then the name, then ``NONE``."""
        sat = self._tracking_now()
        if sat is not None:
            return f"{safe_field(sat.name)}\n"
        return "NONE\n" if self._tracked_once else ""

    def _doppler(self, sat: Satellite, now: datetime) -> str:
        try:
            la = LookAngleCalculator(self.ctx.observer, self.ctx.ut1_utc).compute(sat.satrec, now)
        except PropagationError as exc:
            self.diagnostics.warning(f"propagate-{sat.catalog_number}", "PREDICT GET_DOPPLER %s: %s",
                                     sat.catalog_number, exc)
            return "Huh?\n"
        return _c_float(-100e6 * la.range_rate_km_s / SPEED_OF_LIGHT_KM_S, "%f") + "\n"

    @staticmethod
    def _body(view: BodyView) -> str:
        """az, el, declination, GHA, RA of the Sun or the Moon."""
        return (f"{_c_float(view.azimuth_deg, '%-7.2f')}\n{_c_float(view.elevation_deg, '%+-6.2f')}\n"
                f"{_c_float(view.declination_deg, '%-7.2f')}\n{_c_float(view.greenwich_hour_angle_deg, '%-7.2f')}\n"
                f"{_c_float(view.right_ascension_deg, '%-7.2f')}\n")

    def _next_event(self, sat: Satellite, now: datetime) -> datetime | None:
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
        except PropagationError as exc:
            self.diagnostics.warning(f"propagate-{sat.catalog_number}", "PREDICT GET_SAT %s: %s",
                                     sat.catalog_number, exc)
            return "Huh?\n"
        west = -rep.longitude_deg % 360.0
        event = self._next_event(sat, now)
        next_event = int(event.timestamp()) if event is not None else 0
        eclipse_depth = 0.0 if rep.sunlit else -1.0
        return (f"{safe_field(sat.name)}\n{_c_float(west, '%-7.2f')}\n{_c_float(rep.latitude_deg, '%+-6.2f')}\n"
                f"{_c_float(rep.azimuth_deg, '%-7.2f')}\n{_c_float(rep.elevation_deg, '%+-6.2f')}\n{next_event}\n"
                f"{_c_float(rep.footprint_km, '%-7.2f')}\n{_c_float(rep.range_km, '%-7.2f')}\n"
                f"{_c_float(rep.height_km, '%-7.2f')}\n{_c_float(rep.speed_km_s, '%-7.2f')}\n{rep.rev}\n"
                f"{rep.visibility}\n{_c_float(rep.phase, '%-7.2f')}\n"
                f"{_c_float(eclipse_depth, '%-7.2f')}\n{_c_float(360.0, '%-7.2f')}\n")
