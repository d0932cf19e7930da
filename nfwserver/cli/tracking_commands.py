"""``nfwserver ephemeris``, ``passes`` and ``visible``: InstantTrack's tables on the command line.

Output columns are stable (other tools read them).  CSV: a header row, times ISO-8601 UTC with
milliseconds and ``Z``, numbers with at least six decimals.
"""

from __future__ import annotations

import argparse
import csv
import sys
from datetime import datetime, timedelta

from nfwserver.cli.tracking_options import add_tracking_options, format_time, load_tracking_inputs, parse_time

EPHEMERIS_COLUMNS = ["time_utc", "azimuth_deg", "elevation_deg", "range_km", "range_rate_km_s", "above_horizon"]
PASS_COLUMNS = ["catalog_number", "name", "aos_utc", "tca_utc", "los_utc", "max_elevation_deg",
                "aos_azimuth_deg", "los_azimuth_deg", "duration_s"]
VISIBLE_COLUMNS = ["catalog_number", "name", "azimuth_deg", "elevation_deg", "range_km", "range_rate_km_s"]


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser("ephemeris", help="position table of one satellite",
                              description="Look angles of one satellite at regular steps (InstantTrack's table).")
    add_tracking_options(p)
    p.add_argument("--sat", required=True, help="catalog number (or DDE/element name)")
    p.add_argument("--start", required=True, help="ISO-8601 start (UTC when no zone is given)")
    p.add_argument("--duration", type=float, default=3600.0, metavar="SECONDS")
    p.add_argument("--step", type=float, default=60.0, metavar="SECONDS")
    p.set_defaults(func=run_ephemeris)

    p = subparsers.add_parser("passes", help="AOS/TCA/LOS of satellites over a window",
                              description="Passes over the horizon table; all satellites when no --sat is given.")
    add_tracking_options(p)
    p.add_argument("--sat", action="append", default=[], help="catalog number or name; repeatable")
    p.add_argument("--start", required=True, help="ISO-8601 start (UTC when no zone is given)")
    p.add_argument("--hours", type=float, default=24.0)
    p.add_argument("--workers", type=int, default=1, metavar="N",
                   help="worker processes for large catalogs (POSIX; default 1)")
    p.set_defaults(func=run_passes)

    p = subparsers.add_parser("visible", help="satellites above the horizon table at an instant",
                              description="Every satellite above the horizon table at --at, with its look angles.")
    add_tracking_options(p)
    p.add_argument("--at", required=True, help="ISO-8601 instant (UTC when no zone is given)")
    p.set_defaults(func=run_visible)


def _time_arg(text: str, flag: str) -> datetime:
    from nfwserver.cli import CliError

    try:
        return parse_time(text)
    except ValueError as exc:
        raise CliError(f"{flag}: {exc}") from None


def _writer(fmt: str, columns: list[str]):
    """A row writer: CSV with header, or an aligned table."""
    if fmt == "csv":
        w = csv.writer(sys.stdout, lineterminator="\n")
        w.writerow(columns)
        return w.writerow, lambda: None
    rows: list[list[str]] = []

    def flush() -> None:
        widths = [max(len(c), *(len(r[i]) for r in rows)) if rows else len(c) for i, c in enumerate(columns)]
        print("  ".join(c.ljust(w) for c, w in zip(columns, widths)).rstrip())
        for r in rows:
            print("  ".join(v.rjust(w) if v[:1].isdigit() or v[:1] == "-" else v.ljust(w)
                            for v, w in zip(r, widths)).rstrip())

    return rows.append, flush


def _num(value: float | None, decimals: int, fmt: str) -> str:
    if value is None:
        return ""
    return f"{value:.{max(decimals, 6) if fmt == 'csv' else decimals}f}"


def run_ephemeris(args: argparse.Namespace) -> int:
    from nfwserver.cli import CliError
    from nfwserver.tracking.look_angles import LookAngleCalculator, PropagationError

    start = _time_arg(args.start, "--start")
    if not args.step > 0 or not args.duration >= 0 or args.duration / args.step > 10_000_000:
        raise CliError("--step must be positive and --duration / --step at most 10,000,000")
    inputs = load_tracking_inputs(args)
    sat = inputs.catalog.find(str(args.sat))
    if sat is None:
        raise CliError(f"satellite {args.sat} is not in the element files")
    calc = LookAngleCalculator(inputs.observer, inputs.ut1_utc)
    write, flush = _writer(args.format, EPHEMERIS_COLUMNS)
    count = int(args.duration // args.step) + 1
    for k in range(count):
        when = start + timedelta(seconds=k * args.step)
        try:
            la = calc.compute(sat.satrec, when)
        except PropagationError as exc:
            print(f"nfwserver: {format_time(when)}: {exc}", file=sys.stderr)
            continue
        up = inputs.horizon.is_above(la.azimuth_deg, la.elevation_deg)
        write([format_time(when), _num(la.azimuth_deg, 2, args.format), _num(la.elevation_deg, 2, args.format),
               _num(la.range_km, 1, args.format), _num(la.range_rate_km_s, 4, args.format), "Y" if up else "N"])
    flush()
    return 0


def run_passes(args: argparse.Namespace) -> int:
    from nfwserver.cli import CliError
    from nfwserver.tracking.passes import find_passes

    start = _time_arg(args.start, "--start")
    if not 0 < args.hours <= 24 * 31:
        raise CliError("--hours must be between 0 and 744")
    inputs = load_tracking_inputs(args)
    if args.sat:
        sats = []
        for text in args.sat:
            sat = inputs.catalog.find(text)
            if sat is None:
                raise CliError(f"satellite {text} is not in the element files")
            sats.append(sat)
    else:
        sats = inputs.catalog.satellites()
    if not 1 <= args.workers <= 64:
        raise CliError("--workers must be between 1 and 64")
    passes = find_passes(sats, inputs.observer, start, start + timedelta(hours=args.hours),
                         horizon=inputs.horizon, ut1_utc=inputs.ut1_utc, workers=args.workers)
    write, flush = _writer(args.format, PASS_COLUMNS)
    for p in passes:
        sat = inputs.catalog.get(p.catalog_number)
        write([str(p.catalog_number), sat.name or sat.dde_name,
               format_time(p.aos) if p.aos else "", format_time(p.tca), format_time(p.los) if p.los else "",
               _num(p.max_elevation_deg, 1, args.format), _num(p.aos_azimuth_deg, 1, args.format),
               _num(p.los_azimuth_deg, 1, args.format), _num(p.duration_s, 0, args.format)])
    flush()
    return 0


def run_visible(args: argparse.Namespace) -> int:
    import numpy as np

    from nfwserver.tracking.look_angles import look_angles_array
    from nfwserver.tracking.timescale import julian_date

    at = _time_arg(args.at, "--at")
    inputs = load_tracking_inputs(args)
    sats = inputs.catalog.satellites()
    jd, fr = julian_date(at)
    arr = look_angles_array([s.satrec for s in sats], inputs.observer, np.array([jd]), np.array([fr]),
                            inputs.ut1_utc)
    az, el = arr.azimuth_deg[:, 0], arr.elevation_deg[:, 0]
    with np.errstate(invalid="ignore"):
        up = np.flatnonzero(el > inputs.horizon.min_elevation_array(np.nan_to_num(az)))
    write, flush = _writer(args.format, VISIBLE_COLUMNS)
    for i in up[np.argsort(-el[up])]:
        sat = sats[i]
        write([str(sat.catalog_number), sat.name or sat.dde_name, _num(az[i], 2, args.format),
               _num(el[i], 2, args.format), _num(arr.range_km[i, 0], 1, args.format),
               _num(arr.range_rate_km_s[i, 0], 4, args.format)])
    flush()
    return 0
