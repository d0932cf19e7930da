"""Make ``nfwserver/web/static/land.json`` (the dashboard's offline world map) from Natural Earth.

Input: ``land-110m.json`` of the npm package ``world-atlas`` 2.0.2 (Natural Earth 4.1.0's 1:110m land,
public domain, as TopoJSON; ``npm pack world-atlas@2.0.2``).  Output: the land outlines as rings of
longitude/latitude pairs (degrees, 0.1 degree steps), flattened: ``{"rings": [[lon, lat, lon, lat, ...], ...]}``.

    python3 tools/web/land_from_topojson.py package/land-110m.json nfwserver/web/static/land.json
"""

from __future__ import annotations

import json
import sys


def decode_arcs(topology: dict) -> list[list[tuple[float, float]]]:
    sx, sy = topology["transform"]["scale"]
    tx, ty = topology["transform"]["translate"]
    arcs = []
    for arc in topology["arcs"]:
        x = y = 0
        points = []
        for dx, dy in arc:
            x, y = x + dx, y + dy
            points.append((x * sx + tx, y * sy + ty))
        arcs.append(points)
    return arcs


def ring(arcs: list[list[tuple[float, float]]], indices: list[int]) -> list[tuple[float, float]]:
    out: list[tuple[float, float]] = []
    for index in indices:
        points = arcs[index] if index >= 0 else arcs[~index][::-1]
        out.extend(points if not out else points[1:])
    return out


def main(source: str, target: str) -> None:
    with open(source) as handle:
        topology = json.load(handle)
    arcs = decode_arcs(topology)
    rings = []
    for geometry in topology["objects"]["land"]["geometries"]:
        polygons = geometry["arcs"] if geometry["type"] == "MultiPolygon" else [geometry["arcs"]]
        for polygon in polygons:
            for indices in polygon:
                flat: list[float] = []
                last = None
                for lon, lat in ring(arcs, indices):
                    point = (round(lon, 1), round(lat, 1))
                    if point != last:
                        flat.extend(point)
                        last = point
                if len(flat) >= 6:
                    rings.append(flat)
    with open(target, "w") as out:
        json.dump({"source": "Natural Earth 4.1.0 1:110m land (public domain), via world-atlas 2.0.2",
                   "rings": rings}, out, separators=(",", ":"))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
