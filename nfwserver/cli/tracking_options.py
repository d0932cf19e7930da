"""Options shared by every command that computes positions: elements, observer, horizon, UT1-UTC."""

from __future__ import annotations

import argparse
import logging
import sys
from dataclasses import dataclass
from datetime import datetime, timezone
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # imported when the options are resolved: `--help` and parsing stay light
    from nfwserver.tracking.catalog import Catalog
    from nfwserver.tracking.horizon import HorizonTable
    from nfwserver.tracking.observer import Observer

log = logging.getLogger(__name__)


@dataclass
class TrackingInputs:
    """What the options resolved to."""

    catalog: Catalog
    observer: Observer
    horizon: HorizonTable
    ut1_utc: float


def add_tracking_options(parser: argparse.ArgumentParser, output_format: bool = True) -> None:
    """Add ``--elements``, ``--observer``, ``--horizon``, ``--ut1-utc`` (and ``--format``)."""
    parser.add_argument("--elements", action="append", metavar="FILE", required=True,
                        help="element file (TLE, AMSAT verbose, OMM JSON/CSV); repeatable")
    parser.add_argument("--observer", required=True, metavar="LAT,LON[,ALT_M]|LOCATOR",
                        help="station: e.g. 52.2,0.12,20 or 33.87S,151.21E or JO02ae")
    parser.add_argument("--horizon", metavar="FILE", help="horizon table: 'azimuth elevation' per line")
    parser.add_argument("--ut1-utc", type=float, default=0.0, metavar="SECONDS",
                        help="UT1-UTC in seconds (IERS Bulletin A; default 0)")
    if output_format:
        parser.add_argument("--format", choices=("table", "csv"), default="table", help="output format")


def parse_time(text: str) -> datetime:
    """ISO-8601 time; without a zone it is UTC.  Raises :class:`ValueError` with a clear sentence."""
    raw = text.strip()
    try:
        when = datetime.fromisoformat(raw[:-1] + "+00:00" if raw.endswith(("Z", "z")) else raw)
    except ValueError:
        raise ValueError(f"{text!r} is not an ISO-8601 time (e.g. 2026-05-08T12:00:00Z)") from None
    return when.replace(tzinfo=timezone.utc) if when.tzinfo is None else when.astimezone(timezone.utc)


def format_time(when: datetime) -> str:
    """UTC with milliseconds (truncated) and Z: ``2026-05-08T12:00:00.000Z`` (no ``strftime``: this runs
    once per table cell)."""
    if when.utcoffset():
        when = when.astimezone(timezone.utc)
    return (f"{when.year:04d}-{when.month:02d}-{when.day:02d}T{when.hour:02d}:{when.minute:02d}:"
            f"{when.second:02d}.{when.microsecond // 1000:03d}Z")


def load_tracking_inputs(args: argparse.Namespace) -> TrackingInputs:
    """Resolve the options; rejected element sets are reported on stderr.

    Raises :class:`nfwserver.cli.CliError` when nothing usable remains.
    """
    from nfwserver.cli import CliError
    from nfwserver.tracking.catalog import Catalog
    from nfwserver.tracking.elements import load_element_file
    from nfwserver.tracking.horizon import HorizonTable, load_horizon
    from nfwserver.tracking.observer import parse_observer

    try:
        observer = parse_observer(args.observer)
    except ValueError as exc:
        raise CliError(f"--observer: {exc}") from None
    horizon = HorizonTable()
    if getattr(args, "horizon", None):
        try:
            horizon = load_horizon(args.horizon)
        except (OSError, ValueError) as exc:
            raise CliError(f"--horizon: {exc}") from None
    ut1_utc = float(getattr(args, "ut1_utc", 0.0) or 0.0)
    if not -1.0 <= ut1_utc <= 1.0:
        raise CliError(f"--ut1-utc {ut1_utc} s is outside -1..1 s")
    sets = []
    for path in args.elements:
        result = load_element_file(path)
        for rejection in result.rejected:
            print(f"nfwserver: skipped element set: {rejection}", file=sys.stderr)
        sets.extend(result.sets)
    if not sets:
        raise CliError("no usable element sets in " + ", ".join(args.elements))
    return TrackingInputs(Catalog(sets), observer, horizon, ut1_utc)
