"""Horizon table: the minimum elevation (degrees) at which a satellite counts as "up", by azimuth.

Azimuths are degrees clockwise from true north.  Between table points the minimum elevation is
interpolated linearly, wrapping around from the last point to the first through 360 degrees;
a table with one point is constant and an empty table means a flat 0-degree horizon.

Text format: one ``azimuth elevation`` pair per line (degrees; comma or blanks between them),
``#`` starts a comment, blank lines are ignored.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Iterable
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # numpy is imported by the array methods only: reading a configuration stays light
    import numpy as np


class HorizonTable:
    """Minimum elevation by azimuth; immutable once built."""

    __slots__ = ("_az", "_el", "_ext_az", "_ext_el", "minimum")

    def __init__(self, points: Iterable[tuple[float, float]] = ()) -> None:
        pts: dict[float, float] = {}
        for az, el in points:
            az, el = float(az), float(el)
            if not (math.isfinite(az) and math.isfinite(el)):
                raise ValueError("horizon azimuth and elevation must be finite numbers")
            if not -90.0 <= el <= 90.0:
                raise ValueError(f"horizon elevation {el} is outside -90..90 degrees")
            pts[az % 360.0] = el
        self._az = sorted(pts)
        self._el = [pts[a] for a in self._az]
        if self._az:
            # Extend by one point on each side so interpolation wraps through 360.
            self._ext_az = [self._az[-1] - 360.0, *self._az, self._az[0] + 360.0]
            self._ext_el = [self._el[-1], *self._el, self._el[0]]
        else:
            self._ext_az, self._ext_el = [], []
        #: The lowest minimum elevation anywhere (0 for a flat horizon).
        self.minimum = min(self._el) if self._el else 0.0

    @property
    def points(self) -> list[tuple[float, float]]:
        """The table's (azimuth, elevation) points, sorted by azimuth."""
        return list(zip(self._az, self._el))

    @property
    def is_flat(self) -> bool:
        """True when every azimuth has the same minimum elevation."""
        return len(set(self._el)) <= 1

    def min_elevation(self, azimuth_deg: float) -> float:
        """Minimum elevation (deg) at ``azimuth_deg``."""
        n = len(self._az)
        if n == 0:
            return 0.0
        if n == 1:
            return self._el[0]
        az = azimuth_deg % 360.0
        ext = self._ext_az
        i = bisect.bisect_right(ext, az)
        a0, a1 = ext[i - 1], ext[i]
        e0, e1 = self._ext_el[i - 1], self._ext_el[i]
        return e0 + (e1 - e0) * (az - a0) / (a1 - a0)

    def min_elevation_array(self, azimuth_deg: np.ndarray) -> np.ndarray:
        """Vectorised :meth:`min_elevation` over an array of azimuths (degrees)."""
        import numpy as np

        az = np.asarray(azimuth_deg, dtype=float)
        if len(self._az) == 0:
            return np.zeros_like(az)
        if len(self._az) == 1:
            return np.full_like(az, self._el[0])
        return np.interp(az % 360.0, self._az, self._el, period=360.0)

    def slope_array(self, azimuth_deg: np.ndarray) -> np.ndarray:
        """d(minimum elevation)/d(azimuth) (deg/deg) at each azimuth; 0 for a flat table."""
        import numpy as np

        az = np.asarray(azimuth_deg, dtype=float)
        if len(self._az) < 2:
            return np.zeros_like(az)
        ext_az = np.array(self._ext_az)
        slopes = np.diff(self._ext_el) / np.diff(ext_az)
        idx = np.clip(np.searchsorted(ext_az, az % 360.0, side="right") - 1, 0, len(slopes) - 1)
        return slopes[idx]

    def is_above(self, azimuth_deg: float, elevation_deg: float) -> bool:
        """True when ``elevation_deg`` is above the table's minimum at ``azimuth_deg``."""
        return elevation_deg > self.min_elevation(azimuth_deg)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, HorizonTable) and self.points == other.points

    def __hash__(self) -> int:
        return hash(tuple(self.points))

    def __repr__(self) -> str:
        return f"HorizonTable({self.points!r})"


def parse_horizon(text: str, source: str = "<horizon>") -> HorizonTable:
    """Parse the text format described in the module docstring.

    Raises :class:`ValueError` naming the source and line of the first bad line.
    """
    points = []
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].replace(",", " ").strip()
        if not line:
            continue
        fields = line.split()
        if len(fields) != 2:
            raise ValueError(f"{source} line {number}: expected 'azimuth elevation', got {raw.strip()!r}")
        try:
            az, el = float(fields[0]), float(fields[1])
        except ValueError:
            raise ValueError(f"{source} line {number}: {raw.strip()!r} is not two numbers") from None
        if not (math.isfinite(az) and math.isfinite(el)) or not -90.0 <= el <= 90.0 or not 0 <= az <= 360:
            raise ValueError(
                f"{source} line {number}: azimuth must be 0..360 and elevation -90..90 degrees"
            )
        points.append((az, el))
    return HorizonTable(points)

