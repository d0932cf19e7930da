"""``nfwserver ephemeris``, ``passes`` and ``visible``: InstantTrack's tables on the command line.

Output columns are stable (other tools read them).  CSV: a header row, times ISO-8601 UTC with
milliseconds and ``Z``, numbers with at least six decimals.  ``passes`` ends each row with
``in_progress`` (``Y`` for a pass already under way at the start; its AOS lies before the start).

Every option defaults to the configured station (:mod:`nfwserver.cli.tracking_options`) and the
time to now.  ``visible`` and ``passes`` leave out objects whose positions cannot be trusted at the
time asked (:mod:`nfwserver.tracking.screening`) and name the stale element sets on stderr.
"""

from __future__ import annotations

import argparse
import csv
import sys
from datetime import datetime, timedelta

from nfwserver.cli.arguments import number_in, satellite_value, time_value
from nfwserver.cli.tracking_options import add_tracking_options, format_time, load_tracking_inputs, warn

EPHEMERIS_COLUMNS = ["time_utc", "azimuth_deg", "elevation_deg", "range_km", "range_rate_km_s", "above_horizon"]
PASS_COLUMNS = ["catalog_number", "name", "aos_utc", "tca_utc", "los_utc", "max_elevation_deg",
                "aos_azimuth_deg", "los_azimuth_deg", "duration_s", "in_progress"]
VISIBLE_COLUMNS = ["catalog_number", "name", "azimuth_deg", "elevation_deg", "range_km", "range_rate_km_s"]
TIME_HELP = "'now' (default), relative (+2h, -30m, +90s, +1d) or ISO-8601 (UTC when no zone is given)"
MAX_DURATION_S = 366 * 86400.0


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser("ephemeris", help="position table of one satellite",
                              description="Look angles of one satellite at regular steps (InstantTrack's table). "
                              "Defaults: the configured observer, horizon, catalog and satellite, from now.")
    add_tracking_options(p)
    p.add_argument("--sat", type=satellite_value, help="catalog number or name (default: [server] satellite)")
    p.add_argument("--start", type=time_value, default="now", help=TIME_HELP)
    p.add_argument("--duration", type=number_in(0, MAX_DURATION_S, unit="s"), default=3600.0, metavar="SECONDS")
    p.add_argument("--step", type=number_in(0, MAX_DURATION_S, low_open=True, unit="s"), default=60.0,
                   metavar="SECONDS")
    p.set_defaults(func=run_ephemeris, usage_error=p.error)

    p = subparsers.add_parser("passes", help="AOS/TCA/LOS of satellites over a window",
                              description="Passes over the horizon table; all satellites when no --sat is given. "
                              "A pass already in progress at the start is marked (in_progress Y).")
    add_tracking_options(p)
    p.add_argument("--sat", type=satellite_value, action="append", default=[],
                   help="catalog number or name; repeatable")
    p.add_argument("--start", type=time_value, default="now", help=TIME_HELP)
    p.add_argument("--hours", type=number_in(0, 744, low_open=True, unit="h"), default=24.0)
    p.add_argument("--workers", type=number_in(1, 64, integer=True), default=1, metavar="N",
                   help="worker processes for large catalogs (POSIX; default 1)")
    p.set_defaults(func=run_passes)

    p = subparsers.add_parser("visible", help="satellites above the horizon table at an instant",
                              description="Every satellite above the horizon table at --at, with its look angles.")
    add_tracking_options(p)
    p.add_argument("--at", type=time_value, default="now", help=TIME_HELP)
    p.set_defaults(func=run_visible)


def _pick(catalog, text: str):
    """The satellite ``text`` names (catalog number, DDE or element name); CliError when absent."""
    from nfwserver.cli import CliError

    sat = catalog.find(text)
    if sat is None:
        raise CliError(f"satellite {text} is not in the catalog")
    return sat


def _screen(sats: list, inputs, at: datetime) -> list:
    """The satellites whose positions at ``at`` are usable; the rest and stale sets are reported."""
    from nfwserver.tracking.screening import STALE_AFTER_DAYS, screen_satellites, stale_satellites

    screened = screen_satellites(sats, inputs.observer, at, inputs.ut1_utc)
    if screened.unusable:
        names = ", ".join(s.dde_name for s in screened.unusable[:5]) + (", ..." if len(screened.unusable) > 5 else "")
        warn(f"skipped {len(screened.unusable)} object(s) whose position at {format_time(at)} cannot be computed "
             f"or is implausibly far (decayed or elements far outside their validity): {names}")
    stale = stale_satellites(screened.usable, at)
    if stale:
        names = ", ".join(s.dde_name for s in stale[:5]) + (", ..." if len(stale) > 5 else "")
        warn(f"{len(stale)} element set(s) are more than {STALE_AFTER_DAYS:g} days older than {format_time(at)}, "
             f"so their positions drift ({names}); `nfwserver elements update` fetches newer ones")
    return screened.usable


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

    start = args.start
    if args.duration / args.step > 10_000_000:
        args.usage_error("--duration / --step gives more than 10,000,000 rows: use a larger --step")
    inputs = load_tracking_inputs(args)
    if args.sat is None and inputs.satellite is None:
        raise CliError("no --sat given and no [server] satellite configured")
    sat = _pick(inputs.catalog, str(args.sat if args.sat is not None else inputs.satellite))
    _screen([sat], inputs, start)
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
    from nfwserver.tracking.passes import find_passes

    start = args.start
    inputs = load_tracking_inputs(args)
    sats = [_pick(inputs.catalog, text) for text in args.sat] if args.sat else inputs.catalog.satellites()
    sats = _screen(sats, inputs, start)
    passes = find_passes(sats, inputs.observer, start, start + timedelta(hours=args.hours),
                         horizon=inputs.horizon, ut1_utc=inputs.ut1_utc, workers=args.workers)
    write, flush = _writer(args.format, PASS_COLUMNS)
    for p in passes:
        sat = inputs.catalog.get(p.catalog_number)
        if sat is None:  # passes are only found for catalog satellites
            continue
        write([str(p.catalog_number), sat.name or sat.dde_name,
               format_time(p.aos) if p.aos else "", format_time(p.tca), format_time(p.los) if p.los else "",
               _num(p.max_elevation_deg, 1, args.format), _num(p.aos_azimuth_deg, 1, args.format),
               _num(p.los_azimuth_deg, 1, args.format), _num(p.duration_s, 0, args.format),
               "Y" if p.aos_before_start else "N"])
    flush()
    return 0


def run_visible(args: argparse.Namespace) -> int:
    import numpy as np

    from nfwserver.tracking.look_angles import look_angles_array
    from nfwserver.tracking.screening import MAX_PLAUSIBLE_RANGE_KM
    from nfwserver.tracking.timescale import julian_date

    at = args.at
    inputs = load_tracking_inputs(args)
    sats = _screen(inputs.catalog.satellites(), inputs, at)
    if not sats:
        _writer(args.format, VISIBLE_COLUMNS)[1]()
        return 0
    jd, fr = julian_date(at)
    arr = look_angles_array([s.satrec for s in sats], inputs.observer, np.array([jd]), np.array([fr]),
                            inputs.ut1_utc)
    az, el = arr.azimuth_deg[:, 0], arr.elevation_deg[:, 0]
    with np.errstate(invalid="ignore"):
        up = np.flatnonzero((el > inputs.horizon.min_elevation_array(np.nan_to_num(az)))
                            & (arr.range_km[:, 0] <= MAX_PLAUSIBLE_RANGE_KM))
    write, flush = _writer(args.format, VISIBLE_COLUMNS)
    for i in up[np.argsort(-el[up])]:
        sat = sats[i]
        write([str(sat.catalog_number), sat.name or sat.dde_name, _num(az[i], 2, args.format),
               _num(el[i], 2, args.format), _num(arr.range_km[i, 0], 1, args.format),
               _num(arr.range_rate_km_s[i, 0], 4, args.format)])
    flush()
    return 0
