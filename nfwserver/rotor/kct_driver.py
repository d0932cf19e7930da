"""The Kansas City Tracker rotor driver, as a Python object with the KCT service calls.

Each service call of the KCT driver document is a method with an English name (the original
function number is in its docstring).  Angles follow the KCT conventions: azimuth 0..359,
elevation -90..269 (beyond 90 the antennas are tilted over the top).  A call given an invalid
value is ignored as a whole, as the original driver did; methods return False in that case.

The driver runs on an injected clock: :meth:`KctDriver.service` does what the original did on
each clock interrupt -- time/target table processing (entries whose time has come become the
target; entries that expired while waiting are dropped), the parking timer, AOS/LOS
announcements -- and sends the resulting target to the rotor backend, mapped into the rotor's
azimuth range continuously from its last position (so a 359 -> 1 step never becomes a 358-degree
swing on a rotor that can keep turning), with the slew offsets added.
"""

from __future__ import annotations

import enum
import logging
from collections.abc import Callable
from dataclasses import dataclass
from datetime import datetime, timedelta, timezone

from nfwserver.clock import Clock
from nfwserver.ratelimited_log import RateLimitedLog
from nfwserver.rotor.backend import RotorBackend, RotorError, RotorUnavailable
from nfwserver.rotor.geometry import RotorGeometry
from nfwserver.rotor.kct_status import DriverStatus, KctStatusBit
from nfwserver.rotor.kct_table import MAX_CYCLE_MINUTES, NormalEntry, RepetitiveEntry, TableEntryError, decode_entry

log = logging.getLogger(__name__)

ADD_OK, ADD_INVALID, ADD_FULL = 0, 1, 2
#: The version number function 0A reports.
DRIVER_VERSION = 0x0100
#: A table entry more than this late when reached is dropped instead of executed (seconds).
STALE_ENTRY_S = 30.0


class TableMode(enum.IntEnum):
    NORMAL = 0
    REPETITIVE = 1


@dataclass(frozen=True)
class Announcement:
    """What the original sent in Morse: AOS/LOS warbles and text."""

    time: datetime
    kind: str  #: "AOS", "LOS" or "text"
    text: str


@dataclass(frozen=True)
class ParkingParameters:
    delay_minutes: int  #: 0..60; 0 disables parking
    azimuth_deg: int  #: 0..359
    elevation_deg: int  #: 0..90


def _valid_target(el: float, az: float) -> bool:
    return -90.0 <= el <= 269.0 and 0.0 <= az < 360.0


class KctDriver:
    """The driver model; see the module docstring."""

    def __init__(self, clock: Clock, backend: RotorBackend, geometry: RotorGeometry | None = None,
                 elevation_installed: bool = True, utc_offset_hours: int = 0, table_capacity: int = 1000,
                 on_announcement: Callable[[Announcement], None] | None = None) -> None:
        self.clock = clock
        self.backend = backend
        self.geometry = geometry or RotorGeometry()
        self.elevation_installed = elevation_installed
        self.utc_offset_hours = utc_offset_hours
        self.table_capacity = table_capacity
        self.on_announcement = on_announcement
        self.announcements: list[Announcement] = []
        self.warnings = RateLimitedLog(log, clock)  #: repeated device warnings: first, then a count a minute
        self._slew = (0, 0)  # (el, az)
        self._target: tuple[float, float] | None = None  # (el, az) KCT frame
        self._enabled = True
        self._satellite_id = ""
        self._mode = TableMode.NORMAL
        self._cycle_minutes = 0
        self._cycle_start: datetime | None = None
        self._table: list[NormalEntry | RepetitiveEntry] = []
        self._processing = True
        self._parking = ParkingParameters(0, 0, 0)
        self._park_timer_started: datetime | None = None
        self._rotor_az: float | None = None  # last commanded rotor-frame azimuth (continuity reference)
        self._sent: tuple[float, float] | None = None
        self._card_absent = False
        self._position: tuple[float, float] | None = None  # rotor frame, last read back
        self._morse_enabled = True
        self._popups = 0

    # -- function 0 ----------------------------------------------------------------------
    def status(self) -> DriverStatus:
        """Function 0: status bits, installation, UTC offset, binary positions."""
        bits = KctStatusBit(0)
        if self._card_absent:
            bits |= KctStatusBit.CARD_ABSENT
        if not self._enabled:
            bits |= KctStatusBit.DISABLED
        pos = self._position
        if pos is not None and self._sent is not None:
            daz, delev = self._sent[0] - pos[0], self._sent[1] - pos[1]
            if abs(daz) > 0.5:
                bits |= KctStatusBit.AZ_MOVING | (KctStatusBit.AZ_INCREASING if daz > 0 else 0)
            if abs(delev) > 0.5:
                bits |= KctStatusBit.EL_MOVING | (KctStatusBit.EL_INCREASING if delev > 0 else 0)
        az_bin = el_bin = 0
        if pos is not None:
            g = self.geometry
            az_bin = round((pos[0] - g.az_min) / (g.az_max - g.az_min) * 255)
            el_bin = round((pos[1] - g.el_min) / (g.el_max - g.el_min) * 255)
        return DriverStatus(bits, self.elevation_installed, self.utc_offset_hours,
                            min(max(el_bin, 0), 255), min(max(az_bin, 0), 255))

    # -- functions 1 and 2 -----------------------------------------------------------------
    def read_slew(self) -> tuple[int, int]:
        """Function 1: (elevation, azimuth) slew offsets, degrees."""
        return self._slew

    def write_slew(self, elevation_deg: int, azimuth_deg: int) -> bool:
        """Function 2: set slew offsets (-25..+25 each); an invalid value ignores the call."""
        if not all(isinstance(v, int) and -25 <= v <= 25 for v in (elevation_deg, azimuth_deg)):
            return False
        self._slew = (elevation_deg, azimuth_deg)
        self._push()
        return True

    # -- functions 3 and 4 -----------------------------------------------------------------
    def positions(self) -> tuple[float | None, float | None, float | None, float | None]:
        """Function 3: (current el, current az, target el, target az), KCT frame."""
        cur_el = cur_az = None
        if self._position is not None:
            cur_az, cur_el = self._position[0] % 360.0, self._position[1]
        tgt_el, tgt_az = self._target if self._target is not None else (None, None)
        return cur_el, cur_az, tgt_el, tgt_az

    def set_target(self, elevation_deg: float, azimuth_deg: float) -> bool:
        """Function 4: point at (el, az); el -90..269, az 0..359 (fractions allowed).  Invalid: ignored."""
        if not _valid_target(elevation_deg, azimuth_deg):
            return False
        self._target = (float(elevation_deg), float(azimuth_deg))
        self._push()
        return True

    def set_reference_azimuth(self, rotor_azimuth_deg: float) -> None:
        """Extension: the rotor-frame azimuth the next target continues from (a pass plan's branch)."""
        self._rotor_az = rotor_azimuth_deg

    # -- table functions -----------------------------------------------------------------
    def clear_table(self) -> None:
        """Function 5."""
        self._table.clear()

    def get_table(self, first: int, count: int) -> tuple[TableMode, list[NormalEntry | RepetitiveEntry]]:
        """Function 6: up to ``count`` records from relative record ``first`` (none if out of range)."""
        if first < 0 or count <= 0 or first >= len(self._table):
            return self._mode, []
        return self._mode, list(self._table[first : first + count])

    def add_entry(self, entry: NormalEntry | RepetitiveEntry | bytes) -> int:
        """Function 7: 0 = added, 1 = invalid parameter, 2 = table full."""
        try:
            if isinstance(entry, bytes | bytearray):
                entry = decode_entry(bytes(entry))
            entry.validate()
        except TableEntryError:
            return ADD_INVALID
        if isinstance(entry, RepetitiveEntry) != (self._mode is TableMode.REPETITIVE):
            return ADD_INVALID
        if len(self._table) >= self.table_capacity:
            return ADD_FULL
        self._table.append(entry)
        if isinstance(entry, NormalEntry):
            self._table.sort(key=lambda e: e.time)  # type: ignore[union-attr]
        else:
            self._table.sort(key=lambda e: e.start_minute)  # type: ignore[union-attr]
        return ADD_OK

    def driver_time(self) -> datetime:
        """Function 8: the driver's UTC date and time."""
        return self.clock.now().astimezone(timezone.utc)

    def enable(self, on: bool) -> None:
        """Function 9: disable stops movements at once; enable resumes."""
        self._enabled = on
        if not on:
            try:
                self.backend.stop()
            except RotorError as exc:
                self.warnings.warning("rotor stop failed", "rotor stop failed: %s", exc)
        else:
            self._push(force=True)

    @property
    def enabled(self) -> bool:
        return self._enabled

    def set_satellite_id(self, text: str) -> None:
        """Function 0B: the 8-character satellite identifier shown by the status display."""
        self._satellite_id = text[:8]

    def set_table_mode(self, mode: TableMode, cycle_minutes: int = 0) -> bool:
        """Function 0C: normal or repetitive mode (cycle 1..10080 minutes); clears the table."""
        if mode is TableMode.REPETITIVE and not 1 <= cycle_minutes <= MAX_CYCLE_MINUTES:
            return False
        self._mode = mode
        self._cycle_minutes = cycle_minutes if mode is TableMode.REPETITIVE else 0
        self._cycle_start = self.clock.now() if mode is TableMode.REPETITIVE else None
        self._table.clear()
        return True

    def table_size(self) -> int:
        """Function 0D: the number of table entries the driver can hold."""
        return self.table_capacity

    def table_info(self) -> tuple[TableMode, str | tuple[int, int]]:
        """Function 0E: mode, and the satellite id (normal) or (cycle period, current minute) (repetitive)."""
        if self._mode is TableMode.REPETITIVE:
            return self._mode, (self._cycle_minutes, self._cycle_minute())
        return self._mode, self._satellite_id

    def set_table_processing(self, on: bool) -> bool:
        """Function 0F: enable/disable table processing; returns the previous setting."""
        previous, self._processing = self._processing, on
        return previous

    def register_popup(self, program_mask: int) -> tuple[bool, int]:
        """Function 0A: a TSR notes its installation; returns (already loaded, driver version).

        The original reserved this for its own pop-ups; it is kept for completeness.
        """
        loaded = bool(self._popups & program_mask)
        self._popups |= program_mask
        return loaded, DRIVER_VERSION

    def announce(self, text: str) -> None:
        """Function 10: text for the annunciator (0xFF/0xFE characters mean AOS/LOS warbles)."""
        if self._morse_enabled:
            self._announce("text", " ".join(text.replace("\xff", " ").replace("\xfe", " ").split()))

    def morse_enabled(self) -> bool:
        """Function 11, subfunction FF: is the annunciator enabled?"""
        return self._morse_enabled

    def set_morse(self, enabled: bool) -> bool:
        """Function 11, subfunctions 00 (disable, dropping queued text) and 01-FE (enable); returns the prior state."""
        prior, self._morse_enabled = self._morse_enabled, enabled
        return prior

    def announce_status(self) -> str:
        """Function 12: send the driver's status on the annunciator whatever its enablement; returns the text."""
        status = self.status()
        cur_el, cur_az, tgt_el, tgt_az = self.positions()
        parts = [f"ST {int(status.bits):02X}"]
        if cur_az is not None:
            parts.append(f"AZ {cur_az:.0f} EL {cur_el:.0f}")
        if tgt_az is not None:
            parts.append(f"TGT {tgt_az:.0f} {tgt_el:.0f}")
        text = " ".join(parts)
        self._announce("text", text)
        return text

    def delete_rest_of_pass(self) -> None:
        """Function 13: drop table entries up to and including the end of the current pass."""
        if not self._table or self._mode is not TableMode.NORMAL:
            return
        cut = len(self._table)
        for i, entry in enumerate(self._table):
            assert isinstance(entry, NormalEntry)
            if i > 0 and entry.first_of_pass:  # the next pass starts here: keep it
                cut = i
                break
            if entry.last_of_pass:
                cut = i + 1
                break
        del self._table[:cut]

    # -- parking (function 14) -------------------------------------------------------------
    def parking_parameters(self) -> ParkingParameters:
        return self._parking

    def set_parking(self, delay_minutes: int, azimuth_deg: int, elevation_deg: int) -> bool:
        if not (0 <= delay_minutes <= 60 and 0 <= azimuth_deg <= 359 and 0 <= elevation_deg <= 90):
            return False
        self._parking = ParkingParameters(delay_minutes, azimuth_deg, elevation_deg)
        self._park_timer_started = None
        return True

    def start_parking_timer(self) -> None:
        if self._parking.delay_minutes > 0:
            self._park_timer_started = self.clock.now()

    def stop_parking_timer(self) -> None:
        self._park_timer_started = None

    # -- the clock interrupt ---------------------------------------------------------------
    def _cycle_minute(self) -> int:
        if self._cycle_start is None or self._cycle_minutes <= 0:
            return 0
        elapsed = (self.clock.now() - self._cycle_start).total_seconds() / 60.0
        return int(elapsed) % self._cycle_minutes

    def _announce(self, kind: str, text: str) -> None:
        item = Announcement(self.clock.now(), kind, text)
        self.announcements.append(item)
        del self.announcements[:-200]
        if self.on_announcement is not None:
            try:
                self.on_announcement(item)
            except Exception:
                log.exception("announcement listener failed")

    def service(self) -> None:
        """Run what the clock interrupt ran, then read the rotor position back."""
        now = self.clock.now()
        if self._processing and self._table:
            if self._mode is TableMode.NORMAL:
                due: NormalEntry | None = None
                while self._table and self._table[0].time <= now:  # type: ignore[union-attr]
                    entry = self._table.pop(0)
                    assert isinstance(entry, NormalEntry)
                    if entry.first_of_pass:
                        self._satellite_id = entry.satellite_id
                        self._announce("AOS", entry.satellite_id)
                        self.stop_parking_timer()
                    if entry.last_of_pass:
                        self._announce("LOS", entry.satellite_id)
                        self.start_parking_timer()
                    if now - entry.time <= timedelta(seconds=STALE_ENTRY_S):
                        due = entry
                if due is not None:
                    self.set_target(due.elevation_deg, due.azimuth_deg)
            else:
                minute = self._cycle_minute()
                segment = None
                for entry in self._table:
                    if isinstance(entry, RepetitiveEntry) and entry.start_minute <= minute:
                        segment = entry
                if segment is not None:
                    el = self._target[0] if self._target else 0.0
                    if self._target is None or self._target[1] != segment.azimuth_deg:
                        self.set_target(el, segment.azimuth_deg)
        parking = self._park_timer_started is not None and self._parking.delay_minutes > 0
        if parking and now - self._park_timer_started >= timedelta(minutes=self._parking.delay_minutes):
            self._park_timer_started = None
            self.set_target(self._parking.elevation_deg, self._parking.azimuth_deg)
        self.read_position()

    def read_position(self) -> tuple[float, float] | None:
        """Read the rotor back (rotor frame); None when it cannot be reached."""
        try:
            self._position = self.backend.get_position()
            self._card_absent = False
            self.warnings.clear("rotor position read failed")
        except RotorUnavailable:
            self._card_absent = True
            return None
        except RotorError as exc:
            self.warnings.warning("rotor position read failed", "rotor position read failed: %s", exc)
            return None
        if self._sent is None and self._card_absent is False and self._target is not None:
            self._push(force=True)  # the rotor came back: send the target again
        return self._position

    def rotor_position(self) -> tuple[float, float] | None:
        """Last read-back position, rotor frame."""
        return self._position

    def _push(self, force: bool = False) -> None:
        if self._target is None or not self._enabled:
            return
        el, az = self._target
        el = self.geometry.clamp_elevation(el + self._slew[0])
        reference = self._rotor_az if self._rotor_az is not None else (self._position[0] if self._position else None)
        rotor_az = self.geometry.nearest_rotor_azimuth((az + self._slew[1]) % 360.0, reference)
        command = (rotor_az, el)
        if command == self._sent and not force:
            return
        try:
            self.backend.set_position(rotor_az, el)
        except RotorUnavailable as exc:
            if not self._card_absent:
                log.warning("rotor unavailable: %s", exc)
            self._card_absent = True
            self._sent = None
            return
        except RotorError as exc:
            self.warnings.error("rotor refused", "rotor refused (%.1f, %.1f): %s", rotor_az, el, exc)
            return
        self._card_absent = False
        self._sent = command
        self._rotor_az = rotor_az
