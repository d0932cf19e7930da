"""Rotor geometry: the azimuth and elevation ranges a rotor can reach, and sky <-> rotor angles.

Sky azimuth is 0..360 clockwise from north.  A rotor's azimuth range may be 0..360 with its stop
at north (the common case), -180..180 or 180..540 with the stop at south, or 0..450 with 90
degrees of overlap; elevation 0..90, or 0..180 for a rotor that can tilt over the top
(FlipAnts-style inverted tracking).  A sky azimuth maps to one or more rotor azimuths
(``az + k*360`` within range); choosing the one nearest to where the rotor points avoids the
358-degree swing a naive 1 -> 359 crossing would cause.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass


@dataclass(frozen=True)
class RotorGeometry:
    """Reachable ranges, degrees (rotor frame)."""

    az_min: float = 0.0
    az_max: float = 360.0
    el_min: float = 0.0
    el_max: float = 90.0

    def __post_init__(self) -> None:
        if not (self.az_max - self.az_min >= 180.0 and self.az_max - self.az_min <= 720.0):
            raise ValueError("the azimuth range must span 180..720 degrees")
        if not (-90.0 <= self.el_min < self.el_max <= 180.0):
            raise ValueError("the elevation range must lie within -90..180 degrees")

    @classmethod
    def preset(cls, name: str) -> RotorGeometry:
        """``"north-stop"`` (0..360), ``"south-stop"`` (-180..180), ``"overlap-450"`` (0..450); add
        ``"+flip"`` for elevation 0..180."""
        base, _, flip = name.partition("+")
        az = {"north-stop": (0.0, 360.0), "south-stop": (-180.0, 180.0), "overlap-450": (0.0, 450.0)}
        if base not in az or flip not in ("", "flip"):
            raise ValueError(f"unknown rotor geometry {name!r}")
        return cls(az[base][0], az[base][1], 0.0, 180.0 if flip else 90.0)

    @property
    def can_flip(self) -> bool:
        return self.el_max >= 180.0 - 1e-9

    def rotor_azimuths(self, sky_az: float) -> list[float]:
        """Every rotor azimuth within range that points at ``sky_az``."""
        base = sky_az % 360.0
        k_lo = math.ceil((self.az_min - base) / 360.0 - 1e-12)
        k_hi = math.floor((self.az_max - base) / 360.0 + 1e-12)
        return [base + 360.0 * k for k in range(k_lo, k_hi + 1)]

    def nearest_rotor_azimuth(self, sky_az: float, current: float | None) -> float:
        """The reachable rotor azimuth for ``sky_az`` closest to ``current`` (any if None)."""
        options = self.rotor_azimuths(sky_az)
        if not options:  # a gap in the range (e.g. 0..350): the nearer edge
            base = sky_az % 360.0
            return min((self.az_min, self.az_max), key=lambda e: abs(((base - e + 180) % 360) - 180))
        if current is None:
            return options[0]
        return min(options, key=lambda a: abs(a - current))


def unwrap(azimuths: Sequence[float]) -> list[float]:
    """Continuous azimuths (steps below 180 degrees) starting from the first value."""
    out: list[float] = []
    for az in azimuths:
        if not out:
            out.append(az % 360.0)
            continue
        step = ((az - out[-1]) + 180.0) % 360.0 - 180.0
        out.append(out[-1] + step)
    return out


def fit_track(geometry: RotorGeometry, sky_azimuths: Sequence[float], current: float | None = None) -> float | None:
    """Offset (a multiple of 360) placing the whole continuous track inside the azimuth range, or None.

    Among feasible offsets, the one whose track starts nearest ``current`` (the rotor's azimuth,
    so the move to AOS is shortest) is chosen, or nearest the middle of the range if unknown.
    """
    if not sky_azimuths:
        return 0.0
    track = unwrap(sky_azimuths)
    lo, hi = min(track), max(track)
    k_lo = math.ceil((geometry.az_min - lo) / 360.0 - 1e-12)
    k_hi = math.floor((geometry.az_max - hi) / 360.0 + 1e-12)
    if k_lo > k_hi:
        return None
    anchor = 0.5 * (geometry.az_min + geometry.az_max) if current is None else current
    return 360.0 * min(range(k_lo, k_hi + 1), key=lambda k: abs(track[0] + 360.0 * k - anchor))
