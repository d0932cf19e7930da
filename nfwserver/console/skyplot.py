"""A polar sky plot in text: zenith in the middle, the horizon on the rim, north up, east right.

Radius is proportional to zenith distance (90 - elevation).  Terminal cells are about twice as high
as wide, so the plot is twice as wide as high in characters.
"""

from __future__ import annotations

import math
from collections.abc import Sequence


def render_sky(track: Sequence[tuple[float, float]], current: tuple[float, float] | None = None,
               rows: int = 11) -> str:
    """The plot as ``rows`` lines: ``.`` pass track, ``@`` the satellite now, ``+`` zenith."""
    rows = max(5, rows | 1)  # odd, so there is a centre row
    cols = 2 * rows + 1
    grid = [[" "] * cols for _ in range(rows)]
    cy, cx = rows // 2, cols // 2
    ry, rx = rows // 2, cols // 2

    def put(az: float, el: float, mark: str) -> None:
        if el < 0:
            return
        r = (90.0 - el) / 90.0
        a = math.radians(az)
        y = int(round(cy - r * ry * math.cos(a)))
        x = int(round(cx + r * rx * math.sin(a)))
        if 0 <= y < rows and 0 <= x < cols:
            grid[y][x] = mark

    for k in range(0, 360, 6):  # the horizon circle
        put(float(k), 0.0, ":")
    grid[cy][cx] = "+"
    for az, el in track:
        put(az, el, ".")
    if current is not None:
        put(*current, "@")
    grid[0][cx], grid[rows - 1][cx], grid[cy][0], grid[cy][cols - 1] = "N", "S", "W", "E"
    return "\n".join("".join(row) for row in grid)
