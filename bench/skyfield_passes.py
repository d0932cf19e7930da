"""The skyfield side of ``python -m bench passes``: the rows ``nfwserver passes`` writes, found with skyfield.

Usage: ``python -m bench.skyfield_passes FILE LAT,LON,ALT_M START HOURS table|csv|json`` (START ISO-8601 UTC).

For every satellite in FILE (three-line TLE): ``EarthSatellite.find_events`` over [START, START + HOURS] at
0 deg (a flat horizon), then the elevation at each culmination and the azimuth at each rise and set from one
``(satellite - topos).at(times).altaz()`` per satellite.  Events become passes (a rise, the highest
culmination before the next set, the set); the rows are sorted by AOS (TCA when there is no AOS), then
catalog number, and written with the columns, number formats and layout of ``nfwserver passes``: ISO times
with milliseconds and ``Z``, numbers with 1 decimal in the table (duration 0) and 6 in CSV and JSON, the
table aligned as nfwserver aligns it, CSV by the ``csv`` module, JSON one object a line.

What differs from nfwserver is what is searched, not what is written: skyfield looks only inside the window,
so a pass in progress at START has no AOS (``in_progress`` Y) and one in progress at the end has no LOS,
where nfwserver finds their true AOS and LOS outside the window.
"""

from __future__ import annotations

import csv
import json
import sys
from datetime import datetime, timezone

from skyfield.api import load, wgs84
from skyfield.iokit import parse_tle_file

COLUMNS = ["catalog_number", "name", "aos_utc", "tca_utc", "los_utc", "max_elevation_deg", "aos_azimuth_deg",
           "los_azimuth_deg", "duration_s", "in_progress"]


def _iso(when: datetime | None) -> str:
    if when is None:
        return ""
    return (f"{when.year:04d}-{when.month:02d}-{when.day:02d}T{when.hour:02d}:{when.minute:02d}:"
            f"{when.second:02d}.{when.microsecond // 1000:03d}Z")


def find_rows(path: str, lat: float, lon: float, alt_m: float, start: datetime, hours: float) -> list[tuple]:
    """(catalog number, name, aos, tca, los, max el, aos az, los az) for every pass, sorted as nfwserver sorts."""
    ts = load.timescale(builtin=True)
    with open(path, "rb") as f:
        satellites = list(parse_tle_file(f, ts))
    topos = wgs84.latlon(lat, lon, elevation_m=alt_m)
    t0 = ts.from_datetime(start)
    t1 = ts.tt_jd(t0.tt + hours / 24.0)
    rows = []
    for sat in satellites:
        t, events = sat.find_events(topos, t0, t1, altitude_degrees=0.0)
        if not len(events):
            continue
        alt, az, _ = (sat - topos).at(t).altaz()
        when = t.utc_datetime()
        elevation, azimuth = alt.degrees, az.degrees
        rise = top = None
        for i, event in enumerate(events.tolist()):
            if event == 0:
                rise, top = i, None
            elif event == 1:
                if top is None or elevation[i] > elevation[top]:
                    top = i
            else:
                rows.append(_row(sat, rise, top, i, when, elevation, azimuth))
                rise = top = None
        if rise is not None or top is not None:
            rows.append(_row(sat, rise, top, None, when, elevation, azimuth))
    rows.sort(key=lambda r: ((r[2] or r[3]), r[0]))
    return rows


def _row(sat, rise, top, fall, when, elevation, azimuth) -> tuple:
    peak = top if top is not None else (rise if rise is not None else fall)
    return (sat.model.satnum, sat.name, when[rise] if rise is not None else None, when[peak],
            when[fall] if fall is not None else None, float(elevation[peak]),
            float(azimuth[rise]) if rise is not None else None, float(azimuth[fall]) if fall is not None else None)


def _cells(row: tuple, decimals: int) -> list[str]:
    catnr, name, aos, tca, los, el, aos_az, los_az = row

    def num(value: float | None, d: int) -> str:
        return "" if value is None else f"{value:.{max(d, decimals)}f}"

    duration = (los - aos).total_seconds() if aos is not None and los is not None else None
    return [str(catnr), name, _iso(aos), _iso(tca), _iso(los), num(el, 1), num(aos_az, 1), num(los_az, 1),
            num(duration, 0), "Y" if aos is None else "N"]


def write(rows: list[tuple], fmt: str, out) -> None:
    """The rows as nfwserver writes them."""
    if fmt == "csv":
        writer = csv.writer(out, lineterminator="\n")
        writer.writerow(COLUMNS)
        writer.writerows(_cells(r, 6) for r in rows)
    elif fmt == "json":
        docs = []
        for r in rows:
            cells = _cells(r, 6)
            doc: dict[str, object] = dict(zip(COLUMNS, cells))
            doc["catalog_number"] = r[0]
            for key in ("max_elevation_deg", "aos_azimuth_deg", "los_azimuth_deg", "duration_s"):
                doc[key] = float(doc[key]) if doc[key] else None  # type: ignore[arg-type]
            for key in ("aos_utc", "los_utc"):
                doc[key] = doc[key] or None
            doc["in_progress"] = cells[-1] == "Y"
            docs.append(json.dumps(doc))
        out.write("[\n" + ",\n".join(docs) + "\n]\n" if docs else "[]\n")
    else:
        table = [_cells(r, 0) for r in rows]
        widths = [max(len(c), *(len(t[i]) for t in table)) if table else len(c) for i, c in enumerate(COLUMNS)]
        out.write("  ".join(c.ljust(w) for c, w in zip(COLUMNS, widths)).rstrip() + "\n")
        for t in table:
            out.write("  ".join(v.rjust(w) if v[:1].isdigit() or v[:1] == "-" else v.ljust(w)
                                for v, w in zip(t, widths)).rstrip() + "\n")


def main(argv: list[str]) -> int:
    path, where, start_text, hours, fmt = argv
    lat, lon, alt_m = (float(x) for x in where.split(","))
    start = datetime.fromisoformat(start_text.replace("Z", "+00:00")).astimezone(timezone.utc)
    write(find_rows(path, lat, lon, alt_m, start, float(hours)), fmt, sys.stdout)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
