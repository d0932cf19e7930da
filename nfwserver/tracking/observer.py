"""The observing station: WGS84 geodetic position and its Earth-fixed (ITRS) coordinates.

Latitude and longitude are geodetic degrees (north and east positive), altitude is metres
above the WGS84 ellipsoid.  Earth-fixed coordinates are kilometres in the ITRS (polar motion
neglected, as SGP4 work usually does).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from nfwserver.tracking.constants import WGS84_A_KM
from nfwserver.tracking.constants import WGS84_E2 as _E2
from nfwserver.tracking.maidenhead import is_locator, locator_to_latlon


@dataclass(frozen=True)
class Observer:
    """A station on the WGS84 ellipsoid."""

    latitude_deg: float
    longitude_deg: float
    altitude_m: float = 0.0

    def __post_init__(self) -> None:
        for name in ("latitude_deg", "longitude_deg", "altitude_m"):
            if not math.isfinite(getattr(self, name)):
                raise ValueError(f"observer {name} must be a finite number")
        if not -90.0 <= self.latitude_deg <= 90.0:
            raise ValueError(f"latitude {self.latitude_deg} is outside -90..90 degrees")
        if not -180.0 <= self.longitude_deg <= 360.0:
            raise ValueError(f"longitude {self.longitude_deg} is outside -180..360 degrees")
        if not -12_000.0 <= self.altitude_m <= 100_000.0:
            raise ValueError(f"altitude {self.altitude_m} m is outside -12000..100000 m")

    def itrs_km(self) -> tuple[float, float, float]:
        """Earth-fixed position (x, y, z) in km."""
        lat = math.radians(self.latitude_deg)
        lon = math.radians(self.longitude_deg)
        sin_lat = math.sin(lat)
        n = WGS84_A_KM / math.sqrt(1.0 - _E2 * sin_lat * sin_lat)
        h = self.altitude_m / 1000.0
        return (
            (n + h) * math.cos(lat) * math.cos(lon),
            (n + h) * math.cos(lat) * math.sin(lon),
            (n * (1.0 - _E2) + h) * sin_lat,
        )

    def enu_basis(self) -> tuple[tuple[float, float, float], ...]:
        """Unit vectors (east, north, up) of the local geodetic frame, in Earth-fixed coordinates."""
        lat = math.radians(self.latitude_deg)
        lon = math.radians(self.longitude_deg)
        sl, cl, so, co = math.sin(lat), math.cos(lat), math.sin(lon), math.cos(lon)
        return ((-so, co, 0.0), (-sl * co, -sl * so, cl), (cl * co, cl * so, sl))

    def __str__(self) -> str:
        ns = "N" if self.latitude_deg >= 0 else "S"
        ew = "E" if self.longitude_deg >= 0 else "W"
        return (
            f"{abs(self.latitude_deg):.5f}{ns} {abs(self.longitude_deg):.5f}{ew} "
            f"{self.altitude_m:.0f} m"
        )


_SUFFIXED = re.compile(r"^\s*([0-9.]+)\s*([NSEWnsew])\s*$")


def _coordinate(text: str, positive: str, negative: str, what: str) -> float:
    text = text.strip()
    match = _SUFFIXED.match(text)
    if match:
        value = float(match.group(1))
        hemi = match.group(2).upper()
        if hemi not in (positive, negative):
            raise ValueError(f"{what} {text!r} must end in {positive} or {negative}")
        return -value if hemi == negative else value
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"{what} {text!r} is not a number (use e.g. 40.5, -40.5 or 40.5{negative})") from None
    if not math.isfinite(value):
        raise ValueError(f"{what} {text!r} is not a finite number")
    return value


def parse_observer(text: str) -> Observer:
    """Parse ``LAT,LON[,ALT_M]`` or a Maidenhead locator into an :class:`Observer`.

    Accepted: signed decimals (``-33.87,151.21,40``, east and north positive), hemisphere
    suffixes (``33.87S,151.21E``, ``40.0N,110.0W,1500``), and 4/6/8-character locators
    (``QF56od``, altitude 0).  Raises :class:`ValueError` with one clear sentence otherwise.
    """
    text = text.strip()
    if is_locator(text) and len(text) >= 4:
        lat, lon = locator_to_latlon(text)
        return Observer(lat, lon, 0.0)
    parts = [p for p in re.split(r"[,\s]+", text) if p]
    if len(parts) not in (2, 3):
        raise ValueError(
            f"observer {text!r} is neither LAT,LON[,ALT_M] (e.g. 40.0N,110.0W,1500) nor a locator (e.g. FN31pr)"
        )
    lat = _coordinate(parts[0], "N", "S", "latitude")
    lon = _coordinate(parts[1], "E", "W", "longitude")
    alt = 0.0
    if len(parts) == 3:
        try:
            alt = float(parts[2].lower().removesuffix("m"))
        except ValueError:
            raise ValueError(f"altitude {parts[2]!r} is not a number of metres") from None
    return Observer(lat, lon, alt)
