"""``nfwserver passes`` for a few satellites over a flat horizon: searched and written without numpy.

``passes --sat ISS`` is the command users run most.  Importing numpy alone takes longer than finding and
writing one satellite's day of passes, so for up to :data:`FEW` satellites under a flat horizon the command
uses :mod:`nfwserver.tracking.few_passes` (the catalog search's passes, in pure Python) and
:mod:`nfwserver.cli.pass_text` (the catalog writer's text, cell by cell).  The element sets, the warnings
and the names shown are those of the catalog path (:func:`nfwserver.cli.tracking_commands.pass_names`).
Anything else (more satellites, an obstructed horizon, a case the small search hands back) goes to the
catalog search.
"""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from nfwserver.cli.tracking_options import TrackingInputs

#: Most satellites searched by the small search (each costs a few milliseconds a day).
FEW = 8


def run_few_passes(args: argparse.Namespace, inputs: TrackingInputs, sets: list[Any]) -> bool:
    """Find and write the passes of ``sets`` if they are few and the horizon is flat; False (nothing written)
    when the catalog search must do it."""
    if not 0 < len(sets) <= FEW or not inputs.horizon.is_flat:
        return False
    from nfwserver.cli.pass_reports import (
        PASS_COLUMNS,
        always_up_note,
        no_passes_warning,
        pass_names,
        wide_table_local_note,
    )
    from nfwserver.cli.pass_text import write_pass_text
    from nfwserver.tracking.few_passes import NeedsCatalogSearch, find_few_passes
    from nfwserver.tracking.timescale import julian_date

    jd, fr = julian_date(args.start)
    try:
        found = find_few_passes([es.transient_satrec() for es in sets], [es.catalog_number for es in sets],
                                inputs.observer, jd, fr, args.hours * 3600.0, inputs.horizon.min_elevation(0.0),
                                inputs.ut1_utc)
    except NeedsCatalogSearch:
        return False
    rows = [row for row in found.rows if row[4] >= args.min_el] if args.min_el != 0.0 else found.rows
    numbers = sorted({row[0] for row in rows})
    names, short_names, searched = pass_names(args, inputs, sets, found.skipped, numbers)
    compact = args.format == "table" and not args.wide
    always_up_note([(short_names if compact else names)[row[0]] for row in rows if row[1] is None and row[3] is None])
    if compact:
        from nfwserver.cli.pass_text import zone_label

        if not rows:
            no_passes_warning(args, searched)
        write_pass_text(rows, args.start, short_names, PASS_COLUMNS, "table", sys.stdout, compact=True,
                        zone=zone_label(args.local, args.start), local=args.local)
        return True
    wide_table_local_note(args)
    write_pass_text(rows, args.start, names, PASS_COLUMNS, args.format, sys.stdout)
    return True
