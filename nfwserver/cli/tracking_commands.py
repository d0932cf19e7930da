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
import sys
from datetime import datetime, timedelta
from typing import TYPE_CHECKING, Any

from nfwserver.cli.arguments import number_in, satellite_value, time_value
from nfwserver.cli.errors import CliError, say
from nfwserver.cli.pass_reports import (
    PASS_COLUMNS,
    always_up_note,
    dde_name_map,
    no_passes_warning,
    pass_names,
    report_stale,
    report_unusable,
    stale_days_of,
    wide_table_local_note,
)
from nfwserver.cli.tracking_options import (
    TIME_HELP,
    TrackingInputs,
    add_tracking_options,
    add_window_options,
    format_time,
    load_tracking_inputs,
)

if TYPE_CHECKING:
    from nfwserver.tracking.catalog import Catalog, Satellite
    from nfwserver.tracking.observer import Observer
    from nfwserver.tracking.pass_records import PassList
    from nfwserver.tracking.pass_spill import SpilledPasses

EPHEMERIS_COLUMNS = ["time_utc", "azimuth_deg", "elevation_deg", "range_km", "range_rate_km_s", "above_horizon"]
VISIBLE_COLUMNS = ["catalog_number", "name", "azimuth_deg", "elevation_deg", "range_km", "range_rate_km_s"]
MAX_DURATION_S = 366 * 86400.0


def register(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
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

    p = subparsers.add_parser(
        "passes", help="AOS/TCA/LOS of satellites over a window (what can I work today?)",
        description="Passes over the horizon table in the next --hours, in AOS order.  Which satellites: "
        "--sat, --group and --favourites (any mix); without them your [satellites] favourites when the "
        "configuration lists some, else every satellite of the catalog (--all forces that).  The table fits "
        "80 columns (--wide: every column, as CSV and JSON give); a pass already in progress at the start "
        "has its AOS before the start.",
        epilog="table columns: sat, name, aos (month-day time), tca, los, max (highest elevation, deg), "
        "rise/set (azimuth at AOS/LOS, deg), min (length, minutes)")
    add_tracking_options(p)
    p.add_argument("--sat", type=satellite_value, action="append", default=[],
                   help="catalog number or name; repeatable")
    p.add_argument("--group", action="append", default=[], metavar="PATTERN",
                   help="satellites whose name matches a shell-style pattern, e.g. 'NOAA*' or 'SO-*'; repeatable")
    p.add_argument("--favourites", action="store_true",
                   help="the configuration's [satellites] favourites (the default when it lists some)")
    p.add_argument("--all", action="store_true", help="every satellite of the catalog, even with favourites set")
    p.add_argument("--min-el", type=number_in(-90, 90, unit="deg"), default=0.0, metavar="DEG",
                   help="only passes whose highest elevation reaches this many degrees (default 0: every pass "
                   "over the horizon table; 10 is a common choice for passes worth working)")
    add_window_options(p, "a table with every column (catalog number, full name, ISO times with milliseconds, "
                       "azimuths, duration in seconds, in_progress)")
    p.add_argument("--workers", type=_workers_value, default="auto", metavar="N|auto",
                   help="worker processes for large catalogs (POSIX; the rows are the same whatever the number); "
                   "auto (the default): one per idle core for 1,000 satellites or more, else 1")
    p.set_defaults(func=run_passes)

    p = subparsers.add_parser("visible", help="satellites above the horizon table at an instant",
                              description="Every satellite above the horizon table at --at, with its look angles.")
    add_tracking_options(p)
    p.add_argument("--at", type=time_value, default="now", help=TIME_HELP)
    p.set_defaults(func=run_visible)


def _workers_value(text: str) -> int | str:
    """``type=`` for ``--workers``: ``auto`` or a whole number from 1 to 64."""
    return "auto" if text.strip().lower() == "auto" else int(number_in(1, 64, integer=True)(text))


def _pick(catalog: Catalog, text: str) -> Satellite:
    """The satellite ``text`` names (catalog number, DDE or element name); CliError when absent."""
    sat = catalog.find(text)
    if sat is None:
        raise CliError(f"satellite {text} is not in the catalog")
    return sat


def _screen(sats: list[Any], catalog: Catalog, observer: Observer, ut1_utc: float, at: datetime,
            stale_days: float) -> list[Any]:
    """The satellites (or element sets) whose positions at ``at`` are usable; the rest and the sets older than
    ``stale_days`` (``[elements] stale_days``) are reported (by DDE name)."""
    from nfwserver.tracking.screening import stale_satellites, usable_mask

    usable = usable_mask(sats, observer, at, ut1_utc).tolist()
    unusable = [s for s, ok in zip(sats, usable) if not ok]
    if unusable:
        sats = [s for s, ok in zip(sats, usable) if ok]
    stale = stale_satellites(sats, at, stale_days)
    names = dde_name_map(unusable[:5] + stale[:5], catalog)
    report_unusable(unusable, names, at)
    report_stale(stale, names, at, stale_days)
    return sats


def run_ephemeris(args: argparse.Namespace) -> int:
    import numpy as np

    from nfwserver.cli.bulk_output import RowWriter
    from nfwserver.cli.output_columns import Flag, Number, Time
    from nfwserver.tracking.look_angles import LookAngleCalculator, PropagationError

    start = args.start
    if args.duration / args.step > 10_000_000:
        args.usage_error("--duration / --step gives more than 10,000,000 rows: use a larger --step")
    inputs = load_tracking_inputs(args)
    if args.sat is None and inputs.satellite is None:
        raise CliError("no --sat given and no [server] satellite configured")
    sat = _pick(inputs.catalog, str(args.sat if args.sat is not None else inputs.satellite))
    _screen([sat], inputs.catalog, inputs.observer, inputs.ut1_utc, start, stale_days_of(inputs))
    calc = LookAngleCalculator(inputs.observer, inputs.ut1_utc)
    writer = RowWriter(EPHEMERIS_COLUMNS, args.format, sys.stdout)
    count = int(args.duration // args.step) + 1
    for b0 in range(0, count, 4096):
        offsets, rows = [], []
        for k in range(b0, min(b0 + 4096, count)):
            when = start + timedelta(seconds=k * args.step)
            try:
                la = calc.compute(sat.satrec, when)
            except PropagationError as exc:
                say(f"{format_time(when)}: {exc}")
                continue
            offsets.append(k * args.step)
            rows.append((la.azimuth_deg, la.elevation_deg, la.range_km, la.range_rate_km_s,
                         inputs.horizon.is_above(la.azimuth_deg, la.elevation_deg)))
        if rows:
            az, el, rng, rr, up = (np.array(c) for c in zip(*rows))
            writer.write([Time("time_utc", start, np.array(offsets)), Number("azimuth_deg", az, 2),
                          Number("elevation_deg", el, 2), Number("range_km", rng, 1),
                          Number("range_rate_km_s", rr, 4), Flag("above_horizon", up)])
    writer.close()
    return 0


def run_passes(args: argparse.Namespace) -> int:
    from nfwserver.cli.few_passes_command import run_few_passes

    inputs = TrackingInputs(args)  # the configuration only if an option leaves a value to it
    for name in ("horizon", "observer", "ut1_utc"):  # resolved (and reported) in this order, before the catalog
        getattr(inputs, name)
    sets = _chosen_sets(args, inputs, inputs.catalog)
    if run_few_passes(args, inputs, sets):  # a few satellites: found and written without numpy
        return 0
    return _run_catalog_passes(args, inputs, sets)


def _run_catalog_passes(args: argparse.Namespace, inputs: TrackingInputs, sets: list[Any]) -> int:
    import numpy as np

    from nfwserver.cli.bulk_output import write_rows
    from nfwserver.cli.pass_rows import above, name_column, wide_columns, write_spilled
    from nfwserver.cli.pass_table import compact_columns
    from nfwserver.cli.search_workers import auto_workers
    from nfwserver.tracking.pass_records import PassList

    start = args.start
    # CSV and JSON are written as they come: the search's passes wait in temporary files, not in memory.
    workers = auto_workers(len(sets)) if args.workers == "auto" else int(args.workers)
    passes, names, short_names, searched = _find_passes(args, inputs, sets, args.format in ("csv", "json"), workers)
    if not isinstance(passes, PassList):
        try:
            always_up_note([names[n] for n in passes.always_up(args.min_el)])
            write_spilled(passes, start, args.min_el, names, PASS_COLUMNS, args.format, sys.stdout, workers)
        finally:
            passes.close()
        return 0
    cols = above(passes.columns, args.min_el)
    numbers = np.array(sorted(names), dtype=np.int64)
    compact = args.format == "table" and not args.wide
    up = cols["catalog_number"][np.isnan(cols["aos_s"]) & np.isnan(cols["los_s"])].tolist()
    always_up_note([(short_names if compact else names)[n] for n in up])
    if compact:
        if not len(cols["catalog_number"]):
            no_passes_warning(args, searched)
        write_rows(compact_columns(start, cols, [short_names[n] for n in numbers.tolist()],
                                   np.searchsorted(numbers, cols["catalog_number"]), args.local), "table", sys.stdout,
                   workers)
        return 0
    wide_table_local_note(args)
    write_rows(wide_columns(start, cols, numbers, name_column(numbers, names)), args.format, sys.stdout, workers)
    return 0


def _find_passes(args: argparse.Namespace, inputs: TrackingInputs, sets: list[Any], spilled: bool, workers: int
                 ) -> tuple[PassList | SpilledPasses, dict[int, str], dict[int, str], int]:
    """The passes of ``sets`` over the window the options ask for, found by ``workers`` processes (``spilled``:
    in temporary files, which the caller deletes), the name and the DDE name (at most 12 characters; only for
    the compact table, which alone shows them) to show for each satellite that has one (by catalog number), and
    how many satellites were searched."""
    from nfwserver.tracking.pass_records import PassList
    from nfwserver.tracking.passes import find_passes, find_passes_spilled

    start = args.start
    # The search leaves out the sets unusable at the start (it makes their models anyway); they and the
    # stale sets are reported after it, before any row (the compact table names them with its satellites).
    search = find_passes_spilled if spilled else find_passes
    passes: PassList | SpilledPasses = search(sets, inputs.observer, start, start + timedelta(hours=args.hours),
                                              horizon=inputs.horizon, ut1_utc=inputs.ut1_utc, workers=workers)
    try:
        numbers = passes.catalog_numbers()
        names, short_names, searched = pass_names(args, inputs, sets, passes.skipped, numbers)
    except BaseException:
        if not isinstance(passes, PassList):
            passes.close()
        raise
    return passes, names, short_names, searched


def _chosen_sets(args: argparse.Namespace, inputs: TrackingInputs, catalog: Catalog) -> list[Any]:
    """The element sets ``passes`` searches: --sat, --group, --favourites; else the configured favourites
    (when there are some and no --elements file or --all was given); else the whole catalog."""
    chosen: dict[int, Any] = {}
    for text in args.sat:
        sat = _pick(catalog, text)
        chosen[sat.catalog_number] = sat
    if args.group:
        from nfwserver.cli.pass_table import matching_names  # with numpy: only for --group

        found = matching_names(args.group, ((s.catalog_number, s.dde_name, s.name) for s in catalog))
        if not found:
            raise CliError(f"no satellite's name matches {', '.join(args.group)}")
        chosen.update((n, catalog.get(n)) for n in found)
    default_favourites = not (args.sat or args.group or args.all or args.favourites or getattr(args, "elements", None))
    if args.favourites or default_favourites:
        favourites = inputs.setting("satellites", "favourites")
        if args.favourites and not favourites:
            raise CliError("no favourites configured: list catalog numbers in [satellites] favourites")
        present = [n for n in favourites if catalog.get(n) is not None]
        if default_favourites and present:
            say(f"passes of your {len(present)} favourite(s) ([satellites] favourites); --all for every "
                 "satellite")
        chosen.update((n, catalog.get(n)) for n in present)
    if not chosen and not (args.sat or args.group or args.favourites):
        return catalog.element_sets()
    return [sat.elements for sat in chosen.values() if sat is not None]


def run_visible(args: argparse.Namespace) -> int:
    import numpy as np

    from nfwserver.cli.bulk_output import write_rows
    from nfwserver.cli.output_columns import Integer, Number, Text
    from nfwserver.tracking.look_angles import look_angles_array
    from nfwserver.tracking.screening import MAX_PLAUSIBLE_RANGE_KM
    from nfwserver.tracking.timescale import julian_date

    at = args.at
    inputs = load_tracking_inputs(args)
    sats = _screen(inputs.catalog.satellites(), inputs.catalog, inputs.observer, inputs.ut1_utc, at,
                   stale_days_of(inputs))
    if sats:
        jd, fr = julian_date(at)
        arr = look_angles_array([s.satrec for s in sats], inputs.observer, np.array([jd]), np.array([fr]),
                                inputs.ut1_utc)
        az, el = arr.azimuth_deg[:, 0], arr.elevation_deg[:, 0]
        with np.errstate(invalid="ignore"):
            up = np.flatnonzero((el > inputs.horizon.min_elevation_array(np.nan_to_num(az)))
                                & (arr.range_km[:, 0] <= MAX_PLAUSIBLE_RANGE_KM))
        rows = up[np.argsort(-el[up])]
    else:
        rows = np.empty(0, dtype=np.intp)
        az = el = np.empty(0)
    picked = [sats[i] for i in rows.tolist()]
    write_rows([Integer("catalog_number", np.array([s.catalog_number for s in picked], dtype=np.int64)),
                Text("name", [s.name or s.dde_name for s in picked]), Number("azimuth_deg", az[rows], 2),
                Number("elevation_deg", el[rows], 2),
                Number("range_km", arr.range_km[rows, 0] if sats else np.empty(0), 1),
                Number("range_rate_km_s", arr.range_rate_km_s[rows, 0] if sats else np.empty(0), 4)],
               args.format, sys.stdout)
    return 0
