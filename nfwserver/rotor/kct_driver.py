"""The Kansas City Tracker rotor driver's calls that the station uses, as a Python object.

The station drives the rotor through these service calls of the KCT driver document (the original
function number is in each docstring): status (0), current and target position (3), set target (4) and
parking (14).  Angles follow the KCT conventions: azimuth 0..359, elevation -90..269 (beyond 90 the
antennas are tilted over the top).  The document's other calls (slew offsets, the time/target table and its
modes, enable, satellite id, the Morse annunciator, TSR pop-ups) served DOS programs calling INT 63h; no
client of this server can make them, so they are not modelled.

Invalid and unreachable targets are **ignored, never clamped**.  The document: "If either value is
invalid the entire command will be ignored."  FlipAnts (caution 2): "Your rotor driver program must
ignore any angles that your antennas are not physically capable of ... Your driver must know not to
try to comply."  A target outside -90..269 / 0..359, or one this rotor cannot reach, leaves the previous
target and command as they were; the call returns False and one rate-limited warning says why.  (Clamped,
(el 150, az 280) on a 0..90 elevation rotor would become (280, 90): a different direction from the sky
position (100, 30) it means.)

:meth:`KctDriver.service` does what the clock interrupt did for the station -- the parking timer -- sends
the target mapped into the rotor's azimuth range continuously from its last position (a 359 -> 1 step never
becomes a 358-degree swing), and reads the rotor back, watching for a stall; that side, and how a stall
heals, is :mod:`~nfwserver.rotor.kct_rotor_link`.
"""

from __future__ import annotations

from nfwserver.clock import Clock
from nfwserver.health import LinkHealth
from nfwserver.rotor.backend import RotorBackend
from nfwserver.rotor.geometry import RotorGeometry
from nfwserver.rotor.kct_parking import Parking, ParkingParameters
from nfwserver.rotor.kct_rotor_link import KctRotorLink
from nfwserver.rotor.kct_status import DriverStatus, KctStatusBit

__all__ = ["KctDriver", "ParkingParameters"]


def _valid_target(el: float, az: float) -> bool:
    return -90.0 <= el <= 269.0 and 0.0 <= az < 360.0


class KctDriver(KctRotorLink):
    """The driver model; see the module docstring."""

    def __init__(self, clock: Clock, backend: RotorBackend, geometry: RotorGeometry | None = None,
                 stall_timeout_s: float | None = 15.0, health: LinkHealth | None = None) -> None:
        super().__init__(clock, backend, geometry, stall_timeout_s, health)
        self.parking = Parking()

    # -- function 0 ----------------------------------------------------------------------
    def status(self) -> DriverStatus:
        """Function 0: the status bits (its other values, the installation, UTC offset and binary positions,
        served DOS displays; no face shows them)."""
        bits = KctStatusBit(0)
        if self._card_absent:
            bits |= KctStatusBit.CARD_ABSENT
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
        return DriverStatus(bits)

    # -- functions 3 and 4 -----------------------------------------------------------------
    def positions(self) -> tuple[float | None, float | None, float | None, float | None]:
        """Function 3: (current el, current az, target el, target az), KCT frame."""
        cur_el = cur_az = None
        if self._position is not None:
            cur_az, cur_el = self._position[0] % 360.0, self._position[1]
        tgt_el, tgt_az = self._target if self._target is not None else (None, None)
        return cur_el, cur_az, tgt_el, tgt_az

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
                                      "(az %g..%g, el %g..%g); ignored, not clamped",
                                      elevation_deg, azimuth_deg, self.geometry.az_min, self.geometry.az_max,
                                      self.geometry.el_min, self.geometry.el_max)
            return False
        self._target = (float(elevation_deg), float(azimuth_deg))
        self._push()
        return True

    def set_reference_azimuth(self, rotor_azimuth_deg: float) -> None:
        """Extension: the rotor-frame azimuth the next target continues from (a pass plan's branch)."""
        self._rotor_az = rotor_azimuth_deg

    # -- parking (function 14) -------------------------------------------------------------
    def parking_parameters(self) -> ParkingParameters:
        """Function 14, AL=00h: the parking delay (minutes) and park position (degrees)."""
        return self.parking.parameters

    def set_parking(self, delay_minutes: int, azimuth_deg: int, elevation_deg: int) -> bool:
        """Function 14, AL=01h: set them (from the configuration); False, nothing changed, when out of range."""
        return self.parking.set(delay_minutes, azimuth_deg, elevation_deg)

    def start_parking_timer(self) -> None:
        self.parking.start(self.clock.now())

    def stop_parking_timer(self) -> None:
        self.parking.stop()

    # -- the clock interrupt ---------------------------------------------------------------
    def service(self) -> None:
        """Try a stalled rotor again when its back-off is over, move to the park position when the parking
        timer runs out, then read the rotor position back."""
        if any(self.stall.stalled) and self.health.may_try():
            self._probe("its back-off is over")
        if self.parking.due(self.clock.now()):
            parking = self.parking.parameters
            self.set_target(azimuth_deg=parking.azimuth_deg, elevation_deg=parking.elevation_deg)
        self.read_position()
