"""Options shared by every command that computes positions: configuration, elements, observer, horizon.

Every option defaults to the configured station (README, "Command line"): the observer and horizon from the
configuration (``--config FILE``, else the user's file, else the built-in defaults) and the same
catalog ``nfwserver run`` tracks (:func:`nfwserver.app.station_catalog.load_station_catalog`).
Flags only override.  The configured horizon table describes the obstructions around the
configured station, so it applies only when ``--observer`` is not given (``--horizon`` always wins).
"""

from __future__ import annotations

import argparse
import logging
from datetime import datetime, timezone
from functools import cached_property
from operator import attrgetter
from typing import TYPE_CHECKING, Any

from nfwserver.cli.arguments import number_in, observer_value, time_value
from nfwserver.cli.errors import CliError, load_config_or_fail, say

if TYPE_CHECKING:  # imported when the options are resolved: `--help` and parsing stay light
    from nfwserver.config.schema import Config
    from nfwserver.tracking.catalog import Catalog
    from nfwserver.tracking.horizon import HorizonTable
    from nfwserver.tracking.observer import Observer

log = logging.getLogger(__name__)


class TrackingInputs:
    """What the options resolve to, each value resolved when first read: the configuration is read (once) when
    a value the options leave open needs it: the observer and horizon without ``--observer``, or the station's
    catalog; single settings (UT1-UTC without ``--ut1-utc``, the DDE-name overrides and the limits of an
    ``--elements`` catalog, ``stale_days``) through :meth:`setting`, from the file when there is one."""

    def __init__(self, args: argparse.Namespace) -> None:
        self._args = args
        self._config: Config | None = None

    def config(self) -> Config:
        """The configuration (``--config FILE``, else the user's, else the built-in defaults), read once."""
        if self._config is None:
            if self._file_in_use:
                self._config = load_config_or_fail(getattr(self._args, "config", None))
            else:  # the built-in defaults (the file's absence decided once, for :meth:`setting` too)
                from nfwserver.config.schema import Config

                self._config = Config()
        return self._config

    def setting(self, section: str, key: str) -> Any:
        """``[section] key`` as the configuration in use holds it (:attr:`Setting.where
        <nfwserver.config.setting.Setting.where>`).  Without a file (no ``--config``, and the user has none) that
        is the table's default, read without building the configuration: its records cost a short command
        such as ``passes --sat`` as much at start as its whole search.  A key without a default (the observer,
        the horizon) means what the configuration makes of its absence, so it is always read from that."""
        from nfwserver.config.table import default, setting

        entry = setting(section, key)
        if self._config is None and entry.default is not None and not self._file_in_use:
            return default(section, key)
        return attrgetter(entry.where)(self.config())

    @cached_property
    def _file_in_use(self) -> bool:
        """Whether a configuration file is in use (``--config``, or the user's file), decided once per command."""
        if getattr(self._args, "config", None) is not None:
            return True
        from nfwserver.config.files import default_config_path

        return default_config_path().exists()

    @cached_property
    def _given_observer(self) -> Observer | None:
        from nfwserver.tracking.observer import parse_observer

        observer = getattr(self._args, "observer", None)
        if isinstance(observer, str):  # a parser that did not use observer_value
            try:
                observer = parse_observer(observer)
            except ValueError as exc:
                raise CliError(f"--observer: {exc}") from None
        return observer

    @cached_property
    def horizon(self) -> HorizonTable:
        """``--horizon``, else flat with ``--observer``, else the configured table."""
        from nfwserver.config.files import read_regular_file
        from nfwserver.tracking.horizon import HorizonTable, parse_horizon

        path = getattr(self._args, "horizon", None)
        if path:
            try:  # a regular file only: a FIFO or a terminal named by mistake would block for ever
                return parse_horizon(read_regular_file(path, errors="replace"), source=str(path))
            except FileNotFoundError:
                raise CliError(f"--horizon: no such file: {path}") from None
            except OSError as exc:
                reason = (exc.strerror or type(exc).__name__).lower()
                raise CliError(f"--horizon: cannot read {path} ({reason})") from None
            except ValueError as exc:  # a bad line (named), or not a regular file
                raise CliError(f"--horizon: {exc}") from None
        if self._given_observer is not None:
            return HorizonTable()
        return self.config().horizon

    @cached_property
    def observer(self) -> Observer:
        """``--observer``, else the configured observer (with a warning when none is configured)."""
        observer = self._given_observer
        if observer is None:
            config = self.config()
            observer = config.observer
            if not config.observer_configured:
                say(f"no observer configured: using {observer}; set [observer] location in {config_file(config)} "
                     "(`nfwserver config init` writes a starting file) or give --observer")
        return observer

    @cached_property
    def ut1_utc(self) -> float:
        """``--ut1-utc``, else the configuration's (s)."""
        ut1_utc = getattr(self._args, "ut1_utc", None)
        return float(self.setting("server", "ut1_utc_s") if ut1_utc is None else ut1_utc)

    @cached_property
    def catalog(self) -> Catalog:
        """The ``--elements`` files (rejected sets reported on stderr), else the station's catalog."""
        elements = getattr(self._args, "elements", None)
        if elements:
            return _catalog_from_files(elements, self)
        return _station_catalog(self.config())

    @property
    def satellite(self) -> int | str | None:
        """The configured AutoTracking satellite (``[server] satellite``: a catalog number, or a name that the
        caller resolves as it resolves ``--sat``)."""
        return self.config().server.satellite

    def resolve(self) -> TrackingInputs:
        """Resolve every value now, in the order errors and warnings are reported: horizon and observer,
        UT1-UTC, then the catalog."""
        for name in ("horizon", "observer", "ut1_utc", "catalog"):
            getattr(self, name)
        return self


def add_tracking_options(parser: argparse.ArgumentParser, output_format: bool = True) -> None:
    """Add ``--config``, ``--elements``, ``--observer``, ``--horizon``, ``--ut1-utc`` (and ``--format``)."""
    if "--config" not in parser._option_string_actions:
        parser.add_argument("--config", metavar="FILE",
                            help="configuration file (default: the user's); gives the default observer, "
                                 "horizon and catalog")
    parser.add_argument("--elements", action="append", metavar="FILE",
                        help="element file (TLE, AMSAT verbose, OMM JSON/CSV) to use instead of the station's "
                             "catalog; repeatable")
    parser.add_argument("--observer", type=observer_value, metavar="LAT,LON[,ALT_M]|LOCATOR",
                        help="station instead of the configured one: e.g. 52.2,0.12,20 or 33.87S,151.21E or JO02ae")
    parser.add_argument("--horizon", metavar="FILE",
                        help="horizon table, 'azimuth elevation' per line (default: the configured one, "
                             "unless --observer is given)")
    parser.add_argument("--ut1-utc", type=number_in(-1.0, 1.0, unit="s"), default=None, metavar="SECONDS",
                        help="UT1-UTC in seconds (IERS Bulletin A; default: the configuration's, else 0)")
    if output_format:
        parser.add_argument("--format", choices=("table", "csv", "json"), default="table",
                            help="output format: an aligned table, CSV with a header row, or a JSON array of objects")


TIME_HELP = "'now' (default), relative (+2h, -30m, +90s, +1d) or ISO-8601 (UTC when no zone is given)"


def add_window_options(parser: argparse.ArgumentParser, wide_help: str) -> None:
    """Add the pass tables' ``--start``, ``--hours`` (the window), ``--local`` and ``--wide`` (passes, schedule)."""
    parser.add_argument("--start", type=time_value, default="now", help=TIME_HELP)
    parser.add_argument("--hours", type=number_in(0, 744, low_open=True, unit="h"), default=24.0,
                        help="length of the window from --start, hours (default 24)")
    parser.add_argument("--local", action="store_true",
                        help="table times in this computer's zone, named in the header (default UTC; CSV and JSON "
                        "always give UTC)")
    parser.add_argument("--wide", action="store_true", help=wide_help)


def format_time(when: datetime) -> str:
    """UTC with milliseconds (truncated) and Z: ``2026-05-08T12:00:00.000Z`` (no ``strftime``: this runs
    once per table cell)."""
    if when.utcoffset():
        when = when.astimezone(timezone.utc)
    return (f"{when.year:04d}-{when.month:02d}-{when.day:02d}T{when.hour:02d}:{when.minute:02d}:"
            f"{when.second:02d}.{when.microsecond // 1000:03d}Z")


def config_file(config: Config) -> str:
    """The configuration file ``config`` came from, or the file the user would create."""
    if not config.source.startswith("<"):
        return config.source
    from nfwserver.config.files import default_config_path

    return str(default_config_path())


def _catalog_from_files(paths: list[str], inputs: TrackingInputs) -> Catalog:
    """The sets of the ``--elements`` files, read and checked as the station reads its element files
    (:func:`~nfwserver.app.element_sources.read_file` and :func:`~nfwserver.app.element_sources.parse_source`:
    regular files only, size and set limits, no binary data); a file without sets is named and left out, and
    none at all is a :class:`CliError` naming each file's reason."""
    from nfwserver.app.element_sources import SourceError, SourceLimits, parse_source, read_file
    from nfwserver.tracking.catalog import Catalog

    limits = SourceLimits.of(inputs.setting("elements", "max_source_mib"),
                             inputs.setting("elements", "max_source_sets"))
    sets = []
    unusable: list[str] = []  # why each file gave no set
    for path in paths:
        try:
            data = read_file(path, limits)
        except SourceError as exc:
            raise CliError(str(exc)) from None
        try:
            result = parse_source(data, path, limits)
        except SourceError as exc:
            unusable.append(str(exc))
            continue
        for rejection in result.rejected:
            say(f"skipped element set: {rejection}")
        sets.extend(result.sets)
        del result, data
    if not sets:
        raise CliError("no usable element sets: " + "; ".join(unusable))
    for reason in unusable:
        say(f"left out: {reason}")
    return Catalog(sets, dde_names=inputs.setting("satellites", "names"))


def _station_catalog(config: Config) -> Catalog:
    from nfwserver.app.station_catalog import configured_store, load_station_catalog

    catalog, fetched = load_station_catalog(config)
    for problem in fetched.failed:
        say(f"element source unavailable: {problem}")
    if not len(catalog):
        store = configured_store(config)
        where = f"the stored catalog {store.path} is empty" if store is not None else "no stored catalog"
        raise CliError(f"no element sets: {where}, no [elements] files are configured and the bundled set is "
                       f"off in {config_file(config)}; run `nfwserver elements update FILE|URL` or give --elements")
    return catalog


def load_tracking_inputs(args: argparse.Namespace) -> TrackingInputs:
    """Resolve the options against the configuration now (read first); rejected element sets are reported
    on stderr.  (:class:`TrackingInputs` alone resolves each value when first read.)

    Raises :class:`nfwserver.cli.CliError` when nothing usable remains.
    """
    inputs = TrackingInputs(args)
    inputs.config()
    return inputs.resolve()
