"""FlipAnts-style inverted tracking and the per-pass decision.

Inverted ("flipped") pointing reaches the sky position (az, el) by turning the azimuth rotor to
``(az + 180) mod 360`` and tilting the elevation rotor over the top to ``180 - el``.  A pass that
would carry a north-stop rotor across its stop (say from 350 to 10 degrees) crosses south in
the flipped frame instead, so the rotor follows it without the 360-degree swing.

The decision is taken once, at AOS, for the whole pass (switching mid-pass would swing the
antennas round while the satellite is up): normal pointing if the pass fits the rotor's range,
flipped if only that fits and the elevation rotor can go past 90 degrees, otherwise normal
pointing with the track cut at the stop (reported as not fitting).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from nfwserver.rotor.geometry import RotorGeometry, fit_track


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
        return rotor_az, geometry.clamp_elevation(el)


def plan_pass(geometry: RotorGeometry, track: Sequence[tuple[float, float]],
              current_rotor_az: float | None = None) -> PassPlan:
    """Choose normal or flipped pointing for a pass given as sky (az, el) samples from AOS to LOS.

    ``current_rotor_az`` (rotor frame) picks, among equivalent azimuth branches, the one closest to
    where the rotor is, so the move to AOS is shortest.
    """
    normal = fit_track(geometry, [az for az, _ in track], current_rotor_az)
    if normal is not None:
        return PassPlan(False, normal, True)
    if geometry.can_flip:
        flipped = fit_track(geometry, [flip(az, el)[0] for az, el in track], current_rotor_az)
        if flipped is not None:
            return PassPlan(True, flipped, True)
    return PassPlan(False, 0.0, False)
