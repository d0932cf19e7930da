"""``nfwserver schedule``: the autotrack schedule of a window, every candidate pass scheduled or left out.

The candidate passes are those of the autotrack satellites (``[autotrack] satellites``, else the ``[satellites]
favourites``; ``--sat`` instead, highest priority first) whose highest elevation reaches ``min_el_deg``, found by
the search ``nfwserver passes`` runs (:mod:`nfwserver.autotrack.planner`); the rule is
:mod:`nfwserver.autotrack.rule` (docs/AUTOTRACK.md).  Rows in AOS order with the columns of ``passes``
(:mod:`nfwserver.cli.pass_table`, :mod:`nfwserver.cli.pass_rows`: the same writers) and two more: ``scheduled``
(``Y``/``N``) and ``reason`` (empty when scheduled, else e.g. ``overlaps SO-50 04:09-04:23``, clock times UTC;
with ``--local`` the table's are local).
"""

from __future__ import annotations

import argparse
import sys
from datetime import datetime, timedelta
from typing import TYPE_CHECKING

from nfwserver.cli.arguments import number_in, satellite_value
from nfwserver.cli.errors import CliError, say
from nfwserver.cli.tracking_options import TrackingInputs, add_tracking_options, add_window_options

if TYPE_CHECKING:
    from nfwserver.autotrack.schedule import Schedule
    from nfwserver.cli.output_columns import Column


def register(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = subparsers.add_parser(
        "schedule", help="the autotrack schedule: which passes the station would work by itself",
        description="The passes of the autotrack satellites in the next --hours, in AOS order, each scheduled (Y) "
        "or left out (N) with its reason, by the autotrack rule: taking the satellites in priority order, a pass "
        "is scheduled when it is at least min_gap_s apart from every pass already scheduled (docs/AUTOTRACK.md).  "
        "Satellites: --sat, else [autotrack] satellites, else [satellites] favourites.",
        epilog="columns: those of `nfwserver passes`, then scheduled (Y/N) and reason")
    add_tracking_options(p)
    p.add_argument("--sat", type=satellite_value, action="append", default=[],
                   help="catalog number or name, highest priority first; repeatable (default: [autotrack] "
                   "satellites, else [satellites] favourites)")
    p.add_argument("--min-el", type=number_in(0, 90, unit="deg"), default=None, metavar="DEG",
                   help="a pass counts when its highest elevation reaches this (default: [autotrack] min_el_deg)")
    p.add_argument("--min-gap", type=number_in(0, 3600, unit="s"), default=None, metavar="SECONDS",
                   help="passes closer than this count as overlapping (default: [autotrack] min_gap_s)")
    add_window_options(p, "a table with every column, as CSV and JSON give")
    p.set_defaults(func=run_schedule)


def run_schedule(args: argparse.Namespace) -> int:
    from nfwserver.autotrack.planner import AutotrackSettings, plan_schedule

    inputs = TrackingInputs(args)
    for name in ("horizon", "observer", "ut1_utc"):  # resolved (and reported) in this order, before the catalog
        getattr(inputs, name)
    satellites = tuple(args.sat) or _configured_satellites(inputs)
    if not satellites:
        raise CliError("no satellites to schedule: list them in [autotrack] satellites (or [satellites] "
                       "favourites), or give --sat")
    settings = AutotrackSettings(
        satellites,
        float(inputs.setting("autotrack", "min_el_deg") if args.min_el is None else args.min_el),
        float(inputs.setting("autotrack", "min_gap_s") if args.min_gap is None else args.min_gap))
    start: datetime = args.start
    schedule = plan_schedule(inputs.catalog, inputs.observer, inputs.horizon, inputs.ut1_utc, settings, start,
                             start + timedelta(hours=args.hours))
    for problem in schedule.problems:
        say(f"left out of the schedule: {problem}")
    if not schedule.priorities:
        raise CliError("none of the satellites to schedule is usable")
    _report_stale(inputs, schedule)
    if args.format == "table" and not args.wide:
        if not len(schedule):
            say(f"no passes reaching {settings.min_el_deg:g} deg of the {len(schedule.priorities)} satellite(s) in "
                f"the {args.hours:g} h from {args.start:%Y-%m-%d %H:%M} UTC")
        columns = _compact(schedule, args.local)
    else:
        from nfwserver.cli.pass_reports import wide_table_local_note

        wide_table_local_note(args)
        columns = _wide(schedule, inputs)
    from nfwserver.cli.bulk_output import write_rows

    write_rows(columns, args.format, sys.stdout)
    return 0


def _configured_satellites(inputs: TrackingInputs) -> tuple[int | str, ...]:
    """``[autotrack] satellites``, else ``[satellites] favourites``."""
    listed = inputs.setting("autotrack", "satellites")
    return tuple(inputs.setting("satellites", "favourites")) if listed is None else tuple(listed)


def _report_stale(inputs: TrackingInputs, schedule: Schedule) -> None:
    """Name on stderr the scheduled satellites whose element sets are older than ``[elements] stale_days``."""
    from nfwserver.cli.pass_reports import report_stale, stale_days_of
    from nfwserver.tracking.staleness import stale_satellites

    sats = [s for s in (inputs.catalog.get(n) for n in schedule.priorities) if s is not None]
    stale_days = stale_days_of(inputs)
    report_stale(stale_satellites(sats, schedule.start, stale_days), dict(schedule.names), schedule.start,
                 stale_days)


def _decision_columns(schedule: Schedule, local: bool) -> list[Column]:
    """``scheduled`` (Y/N) and ``reason`` (its clock times in the local zone with ``local``)."""
    import numpy as np

    from nfwserver.cli.output_columns import Text

    offset = (lambda when: when.astimezone().utcoffset() or timedelta(0)) if local else None
    return [Text("scheduled", ["N", "Y"], schedule.decisions.scheduled.astype(np.intp)),
            Text("reason", schedule.reasons(offset))]


def _compact(schedule: Schedule, local: bool) -> list[Column]:
    """The columns of ``passes``' 80-column table, then the decisions."""
    import numpy as np

    from nfwserver.cli.pass_table import compact_columns

    cols = schedule.columns
    numbers = np.array(sorted(schedule.names), dtype=np.int64)
    return [*compact_columns(schedule.start, cols, [schedule.names[n] for n in numbers.tolist()],
                             np.searchsorted(numbers, cols["catalog_number"]), local),
            *_decision_columns(schedule, local)]


def _wide(schedule: Schedule, inputs: TrackingInputs) -> list[Column]:
    """Every column of ``passes`` (CSV, JSON, ``--wide``), then the decisions (UTC)."""
    import numpy as np

    from nfwserver.cli.pass_rows import name_column, wide_columns

    numbers = np.array(sorted(schedule.names), dtype=np.int64)
    names = {}
    for n in numbers.tolist():
        sat = inputs.catalog.get(n)
        names[n] = (sat.name if sat is not None else "") or schedule.names[n]
    return [*wide_columns(schedule.start, schedule.columns, numbers, name_column(numbers, names)),
            *_decision_columns(schedule, False)]
