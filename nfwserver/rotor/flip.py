"""FlipAnts-style inverted tracking and the per-pass decision.

Inverted ("flipped") pointing reaches the sky position (az, el) by turning the azimuth rotor to
``(az + 180) mod 360`` and tilting the elevation rotor over the top to ``180 - el``.  A pass that
would carry a north-stop rotor across its stop (say from 350 to 10 degrees) crosses south in
the flipped frame instead, so the rotor follows it without the 360-degree swing.

The mode is FlipAnts' function 7F (AL=00 normal, AL=01 inverted) or, beyond FlipAnts, ``auto``:

- ``"off"``: normal pointing always;
- ``"on"``: inverted pointing always, as FlipDRV does once switched on.  On a rotor whose elevation
  stops at 90 degrees every inverted target is out of reach, and the driver ignores it (FlipAnts
  caution 1: "Your antennas must be capable of moving 180 degrees in elevation");
- ``"auto"``: decided once, at AOS, for the whole pass (switching mid-pass would swing the antennas
  round while the satellite is up): normal pointing if the pass fits the rotor's range, flipped if
  only that fits and the elevation rotor can go past 90 degrees, otherwise normal pointing as far
  as the stops allow (reported as not fitting).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from nfwserver.rotor.geometry import RotorGeometry, fit_track

#: ``[rotor] flip`` values: per pass, forced inverted (FlipAnts 7F AL=01), forced normal (7F AL=00).
FLIP_MODES = ("auto", "on", "off")


def flip(az_deg: float, el_deg: float) -> tuple[float, float]:
    """Inverted pointing for the sky position (az, el): ((az + 180) mod 360, 180 - el)."""
    return (az_deg + 180.0) % 360.0, 180.0 - el_deg


@dataclass(frozen=True)
class PassPlan:
    """How the rotor follows one pass."""

    flipped: bool
    offset_deg: float  #: added to the continuous (unwrapped) rotor-frame azimuth track
    fits: bool  #: False when no mode keeps the whole pass inside the rotor's range

    def rotor_position(self, geometry: RotorGeometry, sky_az: float, sky_el: float,
                       previous_rotor_az: float | None) -> tuple[float, float]:
        """Rotor-frame (az, el) for a sky position during this pass, continuous with the previous command."""
        az, el = flip(sky_az, sky_el) if self.flipped else (sky_az % 360.0, sky_el)
        if previous_rotor_az is None:
            rotor_az = (az + self.offset_deg) if self.fits else geometry.nearest_rotor_azimuth(az, None)
        else:
            step = ((az - previous_rotor_az) + 180.0) % 360.0 - 180.0
            rotor_az = previous_rotor_az + step
            if not geometry.az_min - 1e-9 <= rotor_az <= geometry.az_max + 1e-9:
                rotor_az = geometry.nearest_rotor_azimuth(az, previous_rotor_az)
        return rotor_az, el


def plan_pass(geometry: RotorGeometry, track: Sequence[tuple[float, float]],
              current_rotor_az: float | None = None, mode: str = "auto") -> PassPlan:
    """Choose normal or flipped pointing for a pass given as sky (az, el) samples from AOS to LOS.

    ``mode`` is one of :data:`FLIP_MODES` (module docstring).  ``current_rotor_az`` (rotor frame)
    picks, among equivalent azimuth branches, the one closest to where the rotor is, so the move to
    AOS is shortest.
    """
    if mode not in FLIP_MODES:
        raise ValueError(f"flip mode must be one of {FLIP_MODES}, not {mode!r}")
    if mode != "on":
        normal = fit_track(geometry, [az for az, _ in track], current_rotor_az)
        if normal is not None:
            return PassPlan(False, normal, True)
    if mode == "on" or (mode == "auto" and geometry.can_flip):
        flipped = fit_track(geometry, [flip(az, el)[0] for az, el in track], current_rotor_az)
        if flipped is not None and geometry.can_flip:
            return PassPlan(True, flipped, True)
        if mode == "on":
            return PassPlan(True, flipped or 0.0, False)
    return PassPlan(False, 0.0, False)
