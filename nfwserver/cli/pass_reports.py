"""What ``passes`` says besides its rows, shared by the catalog search and the few-satellite path: the columns, the
names shown for each satellite, and the notes on stderr (unusable and stale element sets, no passes, satellites up
for the whole window, the wide table's time zone)."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Mapping, Sequence
from datetime import datetime
from typing import TYPE_CHECKING, Any

from nfwserver.cli.errors import say
from nfwserver.cli.tracking_options import TrackingInputs, format_time

if TYPE_CHECKING:
    from nfwserver.tracking.catalog import Catalog

PASS_COLUMNS = ["catalog_number", "name", "aos_utc", "tca_utc", "los_utc", "max_elevation_deg",
                "aos_azimuth_deg", "los_azimuth_deg", "duration_s", "in_progress"]


def report_unusable(unusable: list[Any], names: Mapping[int, str], at: datetime) -> None:
    """Warn of the satellites (or element sets) left out because their positions at ``at`` are unusable,
    naming up to five by DDE name (``names``, by catalog number)."""
    if unusable:
        shown = ", ".join(names[s.catalog_number] for s in unusable[:5]) + (", ..." if len(unusable) > 5 else "")
        say(f"skipped {len(unusable)} object(s) whose position at {format_time(at)} cannot be computed "
             f"or is implausibly far (decayed or elements far outside their validity): {shown}")


def report_stale(stale: list[Any], names: Mapping[int, str], at: datetime, stale_days: float) -> None:
    """Warn of the sets older than ``stale_days`` before ``at``, naming up to five by DDE name (``names``)."""
    if stale:
        shown = ", ".join(names[s.catalog_number] for s in stale[:5]) + (", ..." if len(stale) > 5 else "")
        ages = [(at - getattr(s, "elements", s).epoch).total_seconds() / 86400.0 for s in stale]
        span = f"{min(ages):.0f} to {max(ages):.0f}" if round(min(ages)) != round(max(ages)) else f"{max(ages):.0f}"
        sets, drift = ("1 element set is", "its position drifts") if len(stale) == 1 else \
            (f"{len(stale)} element sets are", "their positions drift")
        say(f"{sets} {span} days old at {format_time(at)} (more than [elements] stale_days, {stale_days:g}), "
            f"so {drift} ({shown}); `nfwserver elements update` fetches newer ones")


def stale_days_of(inputs: TrackingInputs) -> float:
    """``[elements] stale_days`` of the configuration in use."""
    return float(inputs.setting("elements", "stale_days"))


def dde_name_map(items: list[Any], catalog: Catalog, more: Sequence[int] = ()) -> dict[int, str]:
    """The DDE names of satellites or element sets (a satellite's own; the sets' from the catalog) and of the
    catalog numbers ``more``, by catalog number: one naming of the catalog for all of them (each call names
    the whole catalog when nothing has named it yet)."""
    names = {s.catalog_number: s.dde_name for s in items if hasattr(s, "dde_name")}
    wanted = [s.catalog_number for s in items if not hasattr(s, "dde_name")] + [n for n in more if n not in names]
    names.update(zip(wanted, catalog.dde_names_of(wanted)) if wanted else ())
    return names


def no_passes_warning(args: argparse.Namespace, searched: int) -> None:
    """The compact table's line on stderr when no pass is listed."""
    reach = f" reaching {args.min_el:g} deg" if args.min_el else ""
    say(f"no passes{reach} of the {searched} satellite(s) in the {args.hours:g} h from {format_time(args.start)}")


def always_up_note(names: Sequence[str]) -> None:
    """Name on stderr the satellites (``names``) whose rows have neither AOS nor LOS because they stay up."""
    if names:
        shown = ", ".join(names[:5]) + (", ..." if len(names) > 5 else "")
        say(f"up for the whole window (above the horizon from before the search to after it, so no AOS or "
             f"LOS): {shown}")


def wide_table_local_note(args: argparse.Namespace) -> None:
    """``--local`` with ``--wide``: say on stderr that the wide table stays in UTC."""
    if args.local and args.format == "table":
        from nfwserver.cli.pass_text import zone_label

        print(f"times in UTC: --local shortens the table's times only ({zone_label(True, args.start)} here); "
              "drop --wide to see them", file=sys.stderr)


def pass_names(args: argparse.Namespace, inputs: TrackingInputs, sets: list[Any], skipped: Sequence[int],
               numbers: Sequence[int]) -> tuple[dict[int, str], dict[int, str], int]:
    """After a search of ``sets`` that left out ``skipped`` and found passes of ``numbers``: the unusable and
    the stale sets reported on stderr; the name and the DDE name (compact table only) to show for each of
    ``numbers``, and how many satellites were searched."""
    from nfwserver.tracking.staleness import stale_satellites

    compact = args.format == "table" and not args.wide  # the only output that shows DDE names
    stale_days = stale_days_of(inputs)
    left_out = set(skipped)
    unusable = [s for s in sets if s.catalog_number in left_out]
    sets = [s for s in sets if s.catalog_number not in left_out] if left_out else sets
    stale = stale_satellites(sets, args.start, stale_days)
    by_number = {es.catalog_number: es.name for es in sets}
    element_names = {n: by_number[n] for n in numbers}
    # Every DDE name shown (the warnings', the compact table's, those of unnamed sets) from one naming.
    dde = dde_name_map(unusable[:5] + stale[:5], inputs.catalog,
                        numbers if compact else [n for n, name in element_names.items() if not name])
    report_unusable(unusable, dde, args.start)
    report_stale(stale, dde, args.start, stale_days)
    return ({n: name or dde[n] for n, name in element_names.items()}, {n: dde[n] for n in numbers} if compact else {},
            len(sets))
