"""The Kansas City Tracker rotor driver, as a Python object with the KCT service calls.

Each service call of the KCT driver document is a method with an English name (the original
function number is in its docstring).  Angles follow the KCT conventions: azimuth 0..359,
elevation -90..269 (beyond 90 the antennas are tilted over the top).

Invalid and unreachable targets are **ignored, never clamped**.  The document: "If either value is
invalid the entire command will be ignored."  FlipAnts (caution 2): "Your rotor driver program must
ignore any angles that your antennas are not physically capable of ... Your driver must know not to
try to comply."  A target outside -90..269 / 0..359, or one this rotor cannot reach (slew offsets
added), leaves the previous target and command as they were; the call returns False and one
rate-limited warning says why.  (Clamped, (el 150, az 280) on a 0..90 elevation rotor would become
(280, 90): a different direction from the sky position (100, 30) it means.)

:meth:`KctDriver.service` does what the clock interrupt did -- time/target table processing
(:mod:`~nfwserver.rotor.kct_table_store`), the parking timer, AOS/LOS announcements
(:mod:`~nfwserver.rotor.kct_annunciator`) -- sends the target mapped into the rotor's azimuth range
continuously from its last position (a 359 -> 1 step never becomes a 358-degree swing), slew
added, and reads the rotor back, watching for a stall; that side, and how a stall heals, is
:mod:`~nfwserver.rotor.kct_rotor_link`.  Loading the table (function 7) is
told to ``table_load_listeners``: autotracking (:mod:`~nfwserver.rotor.coupling`) then lets go.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from datetime import datetime, timedelta, timezone

from nfwserver.clock import Clock
from nfwserver.health import LinkHealth
from nfwserver.rotor.backend import RotorBackend
from nfwserver.rotor.geometry import RotorGeometry
from nfwserver.rotor.kct_annunciator import Announcement
from nfwserver.rotor.kct_parking import Parking, ParkingParameters
from nfwserver.rotor.kct_rotor_link import KctRotorLink
from nfwserver.rotor.kct_status import DriverStatus, KctStatusBit
from nfwserver.rotor.kct_table import NormalEntry, RepetitiveEntry
from nfwserver.rotor.kct_table_store import ADD_FULL, ADD_INVALID, ADD_OK, TableMode, TableRead, TimeTargetTable

__all__ = ["ADD_FULL", "ADD_INVALID", "ADD_OK", "Announcement", "KctDriver", "ParkingParameters", "TableMode"]

log = logging.getLogger(__name__)

#: The version number function 0A reports.
DRIVER_VERSION = 0x0100
#: A table entry more than this late when reached is dropped instead of executed (seconds).
STALE_ENTRY_S = 30.0


def _valid_target(el: float, az: float) -> bool:
    return -90.0 <= el <= 269.0 and 0.0 <= az < 360.0


class KctDriver(KctRotorLink):
    """The driver model; see the module docstring."""

    def __init__(self, clock: Clock, backend: RotorBackend, geometry: RotorGeometry | None = None,
                 elevation_installed: bool = True, utc_offset_hours: int = 0, table_capacity: int = 1000,
                 on_announcement: Callable[[Announcement], None] | None = None,
                 stall_timeout_s: float | None = 15.0, health: LinkHealth | None = None) -> None:
        super().__init__(clock, backend, geometry, elevation_installed, stall_timeout_s, health)
        self.utc_offset_hours = utc_offset_hours
        self.table = TimeTargetTable(table_capacity)
        if on_announcement is not None:
            self.annunciator.listeners.append(on_announcement)
        self.table_load_listeners: list[Callable[[], None]] = []
        self._satellite_id = ""
        self._processing = True
        self.parking = Parking()
        self._popups = 0

    @property
    def announcements(self) -> list[Announcement]:
        """What the annunciator sent, oldest first (bounded)."""
        return self.annunciator.history

    # -- function 0 ----------------------------------------------------------------------
    def status(self) -> DriverStatus:
        """Function 0: status bits, installation, UTC offset, binary positions."""
        bits = KctStatusBit(0)
        if self._card_absent:
            bits |= KctStatusBit.CARD_ABSENT
        if not self._enabled:
            bits |= KctStatusBit.DISABLED
        if self.stall.stalled[0]:
            bits |= KctStatusBit.AZ_STALLED
        if self.stall.stalled[1]:
            bits |= KctStatusBit.EL_STALLED
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

    def reachable(self, azimuth_deg: float, elevation_deg: float) -> bool:
        """Whether this rotor can point at the KCT target (az, el; degrees) with the current slew offsets."""
        return _valid_target(elevation_deg, azimuth_deg) and self._command_for(elevation_deg, azimuth_deg) is not None

    def set_target(self, azimuth_deg: float, elevation_deg: float) -> bool:
        """Function 4: point at (az, el), degrees; az 0..359, el -90..269 (fractions allowed).  The KCT call
        passes elevation first; this method, like every other call here, takes azimuth first.

        An invalid or unreachable target is ignored as a whole (module docstring); returns False then.
        """
        if not _valid_target(elevation_deg, azimuth_deg):
            self._diagnostics.warning("invalid", "set target el %.1f az %.1f: outside el -90..269 / az 0..359; "
                                      "ignored", elevation_deg, azimuth_deg)
            return False
        if self._command_for(elevation_deg, azimuth_deg) is None:
            self._diagnostics.warning("unreachable", "set target el %.1f az %.1f: this rotor cannot reach it "
                                      "(az %g..%g, el %g..%g, slew el %+d az %+d); ignored, not clamped",
                                      elevation_deg, azimuth_deg, self.geometry.az_min, self.geometry.az_max,
                                      self.geometry.el_min, self.geometry.el_max, *self._slew)
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
        self.table.clear()

    def get_table(self, first: int, count: int) -> TableRead:
        """Function 6: up to ``count`` records from relative record ``first`` as 23-byte images, the mode,
        and (repetitive mode) the relative number of the entry in force."""
        return self.table.read(first, count, self.clock.now())

    def add_entry(self, entry: NormalEntry | RepetitiveEntry | bytes) -> int:
        """Function 7: 0 = added, 1 = invalid parameter, 2 = table full.  Tells ``table_load_listeners``."""
        result = self.table.add(entry)
        for listener in list(self.table_load_listeners):
            try:
                listener()
            except Exception:
                log.exception("table-load listener failed")
        return result

    def driver_time(self) -> datetime:
        """Function 8: the driver's UTC date and time."""
        return self.clock.now().astimezone(timezone.utc)

    def enable(self, on: bool) -> None:
        """Function 9: disable stops movements at once; enable resumes and re-arms stalled axes."""
        self._enabled = on
        if not on:
            self._stop_rotor()
        else:
            self.stall.reset()
            self._push(force=True)

    @property
    def enabled(self) -> bool:
        return self._enabled

    def set_satellite_id(self, text: str) -> None:
        """Function 0B: the 8-character satellite identifier shown by the status display."""
        self._satellite_id = text[:8]

    def set_table_mode(self, mode: TableMode, cycle_minutes: int = 0) -> bool:
        """Function 0C: normal or repetitive mode (cycle 1..10080 minutes); clears the table."""
        return self.table.set_mode(mode, cycle_minutes, self.clock.now())

    def table_size(self) -> int:
        """Function 0D: the number of entries in the table (see :mod:`nfwserver.rotor.kct_table_store`)."""
        return len(self.table)

    @property
    def table_capacity(self) -> int:
        return self.table.capacity

    def table_info(self) -> tuple[TableMode, str | tuple[int, int]]:
        """Function 0E: mode, and the satellite id (normal) or (cycle period, current minute) (repetitive)."""
        if self.table.mode is TableMode.REPETITIVE:
            return self.table.mode, (self.table.cycle_minutes, self.table.cycle_minute(self.clock.now()))
        return self.table.mode, self._satellite_id

    def set_table_processing(self, on: bool) -> bool:
        """Function 0F: enable/disable table processing; returns the previous setting."""
        previous, self._processing = self._processing, on
        return previous

    def register_popup(self, program_mask: int) -> tuple[bool, int]:
        """Function 0A: a TSR notes its installation; returns (already loaded, driver version)."""
        loaded, self._popups = bool(self._popups & program_mask), self._popups | program_mask
        return loaded, DRIVER_VERSION

    def announce(self, text: bytes | str) -> list[Announcement]:
        """Function 10: an ASCIIZ string for the annunciator (rules in :mod:`nfwserver.rotor.kct_annunciator`)."""
        return self.annunciator.send(text)

    def morse_enabled(self) -> bool:
        """Function 11, subfunction FF: is the annunciator enabled?"""
        return self.annunciator.enabled

    def set_morse(self, enabled: bool) -> bool:
        """Function 11, subfunctions 00 (disable, dropping queued text) and 01-FE (enable); returns the prior state."""
        prior, self.annunciator.enabled = self.annunciator.enabled, enabled
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
        self.annunciator.emit("text", text)
        return text

    def delete_rest_of_pass(self) -> None:
        """Function 13: drop table entries up to and including the end of the current pass."""
        self.table.delete_rest_of_pass()

    # -- parking (function 14) -------------------------------------------------------------
    def parking_parameters(self) -> ParkingParameters:
        return self.parking.parameters

    def set_parking(self, delay_minutes: int, azimuth_deg: int, elevation_deg: int) -> bool:
        return self.parking.set(delay_minutes, azimuth_deg, elevation_deg)

    def start_parking_timer(self) -> None:
        self.parking.start(self.clock.now())

    def stop_parking_timer(self) -> None:
        self.parking.stop()

    # -- the clock interrupt ---------------------------------------------------------------
    def service(self) -> None:
        """Run what the clock interrupt ran, try a stalled rotor again when its back-off is over, then
        read the rotor position back."""
        if any(self.stall.stalled) and self._enabled and self.health.may_try():
            self._probe("its back-off is over")
        now = self.clock.now()
        if self._processing and self.table.entries:
            if self.table.mode is TableMode.NORMAL:
                self._process_normal(now)
            else:
                index = self.table.in_force(now)
                segment = self.table.entries[index] if index is not None else None
                if isinstance(segment, RepetitiveEntry):
                    el = self._target[0] if self._target else 0.0
                    if self._target is None or self._target[1] != segment.azimuth_deg:
                        self.set_target(azimuth_deg=segment.azimuth_deg, elevation_deg=el)
        if self.parking.due(now):
            parking = self.parking.parameters
            self.set_target(azimuth_deg=parking.azimuth_deg, elevation_deg=parking.elevation_deg)
        self.read_position()

    def _process_normal(self, now: datetime) -> None:
        due: NormalEntry | None = None
        for entry in self.table.pop_due(now):
            if entry.first_of_pass:
                self._satellite_id = entry.satellite_id
                if self.annunciator.enabled:
                    self.annunciator.emit("AOS", entry.satellite_id)
                self.stop_parking_timer()
            if entry.last_of_pass:
                if self.annunciator.enabled:
                    self.annunciator.emit("LOS", entry.satellite_id)
                self.start_parking_timer()
            if now - entry.time <= timedelta(seconds=STALE_ENTRY_S):
                due = entry
        if due is not None:
            self.set_target(azimuth_deg=due.azimuth_deg, elevation_deg=due.elevation_deg)

