"""Maidenhead grid locators (e.g. ``FN31pr``) to and from geodetic latitude/longitude (degrees).

A locator has 2, 4, 6 or 8 characters: field (letters A-R, 20 x 10 deg), square (digits,
2 x 1 deg), subsquare (letters a-x, 5' x 2.5'), extended square (digits, 30" x 15").
Positions decode to the centre of the smallest box given.
"""

from __future__ import annotations

import re

_LOCATOR = re.compile(r"^[A-Ra-r]{2}(?:[0-9]{2}(?:[A-Xa-x]{2}(?:[0-9]{2})?)?)?$")

# (longitude size, latitude size) in degrees of each pair, and the number of divisions.
_STEPS = ((20.0, 10.0, 18), (2.0, 1.0, 10), (2.0 / 24, 1.0 / 24, 24), (2.0 / 240, 1.0 / 240, 10))


def is_locator(text: str) -> bool:
    """True if ``text`` is a syntactically valid 2/4/6/8-character locator."""
    return bool(_LOCATOR.match(text.strip()))


def locator_to_latlon(locator: str) -> tuple[float, float]:
    """Centre (latitude_deg, longitude_deg) of the box named by ``locator``.

    Raises :class:`ValueError` for an invalid locator.
    """
    loc = locator.strip()
    if not _LOCATOR.match(loc):
        raise ValueError(f"{locator!r} is not a Maidenhead locator (2, 4, 6 or 8 characters, e.g. FN31pr)")
    lon, lat = -180.0, -90.0
    size = _STEPS[0]
    for i in range(0, len(loc), 2):
        size = _STEPS[i // 2]
        a, b = loc[i], loc[i + 1]
        if a.isdigit():
            ia, ib = int(a), int(b)
        else:
            ia, ib = ord(a.upper()) - ord("A"), ord(b.upper()) - ord("A")
        lon += ia * size[0]
        lat += ib * size[1]
    return lat + size[1] / 2.0, lon + size[0] / 2.0


def latlon_to_locator(latitude_deg: float, longitude_deg: float, precision: int = 6) -> str:
    """Locator of ``precision`` characters (2, 4, 6 or 8) for a position in degrees."""
    if precision not in (2, 4, 6, 8):
        raise ValueError("locator precision must be 2, 4, 6 or 8 characters")
    lon = (longitude_deg + 180.0) % 360.0
    lat = min(max(latitude_deg + 90.0, 0.0), 180.0 - 1e-9)
    out = []
    for i in range(precision // 2):
        lon_size, lat_size, count = _STEPS[i]
        ilon = min(int(lon // lon_size), count - 1)
        ilat = min(int(lat // lat_size), count - 1)
        lon -= ilon * lon_size
        lat -= ilat * lat_size
        if i % 2 == 0:
            base = "A" if i == 0 else "a"
            out.append(chr(ord(base) + ilon) + chr(ord(base) + ilat))
        else:
            out.append(f"{ilon}{ilat}")
    return "".join(out)
