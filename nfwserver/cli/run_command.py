"""``nfwserver run``: the station server, with the console on a terminal or headless as a service."""

from __future__ import annotations

import argparse
import logging
import logging.handlers
import signal
import sys
import threading
from pathlib import Path

from nfwserver.clock import SystemClock

log = logging.getLogger("nfwserver")


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "run", help="run the server (console on a terminal, or --headless)",
        description="Run the Nova-compatible DDE server with the configuration file (see `nfwserver config path`), "
        "or with built-in defaults when there is none.",
    )
    p.add_argument("--config", metavar="FILE", help="configuration file (default: the platform's config directory)")
    p.add_argument("--headless", action="store_true", help="no console: run as a service, log to a rotating file")
    p.add_argument("--log-file", metavar="FILE", help="log file for --headless (default: user log directory)")
    p.add_argument("--duration", type=float, metavar="SECONDS", help="stop after this many seconds (for checks)")
    p.set_defaults(func=run)


def _log_to_file(path: Path) -> logging.Handler:
    path.parent.mkdir(parents=True, exist_ok=True)
    handler = logging.handlers.RotatingFileHandler(path, maxBytes=5 * 2**20, backupCount=5, encoding="utf-8")
    handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s"))
    root = logging.getLogger()
    for existing in root.handlers:  # the terminal keeps showing warnings and errors only
        if isinstance(existing, logging.StreamHandler) and not isinstance(existing, logging.FileHandler):
            existing.setLevel(max(existing.level, logging.WARNING))
    root.addHandler(handler)
    root.setLevel(min(root.level, logging.INFO))
    return handler


def run(args: argparse.Namespace) -> int:
    from nfwserver.app.station import Station
    from nfwserver.cli import CliError
    from nfwserver.config import ConfigError, default_config_path, load_config

    try:
        config = load_config(args.config)
    except ConfigError as exc:
        raise CliError(f"configuration refused: {exc}") from None
    if args.duration is not None and not args.duration > 0:
        raise CliError("--duration must be positive")
    hint = ""
    if not config.observer_configured:
        hint = (f"no observer configured: using {config.observer} (Greenwich). Set [observer] location in "
                f"{default_config_path()} (`nfwserver config init` writes a starting file).")
    console = sys.stdout.isatty() and not args.headless
    file_handler = None
    if not console:
        from platformdirs import user_log_dir

        default_log = Path(user_log_dir("nfwserver", appauthor=False)) / "nfwserver.log"
        file_handler = _log_to_file(Path(args.log_file) if args.log_file else default_log)
    station = Station(config, SystemClock())
    try:
        station.start()
    except OSError as exc:
        station.stop()
        raise CliError(f"cannot start the station: {exc}") from None
    notes = [f"configuration: {config.source}", station.transport_note, f"{len(station.catalog)} satellites loaded"]
    if hint:
        notes.append(hint)
    ages = [s.age_days(station.clock.now()) for s in station.catalog]
    if ages and min(ages) > 14:
        stale = (f"the newest element set is {min(ages):.0f} days old: positions drift; add current elements "
                 "([elements] files or urls in the configuration)")
        notes.append(stale)
        hint = f"{hint} {stale}".strip()
    if args.config:
        station.watch_config(args.config)
    try:
        if console:
            from nfwserver.console.app import NfwConsole

            app = NfwConsole(station.core, station.transport_note, hint, radio=station.radio, rotor=station.rotor,
                             favourites=config.favourites or (25544, 27607, 43017, 44909, 7530),
                             clients=station.nova.client_count)
            if args.duration:
                threading.Timer(args.duration, app.exit).start()
            app.run()
        else:
            for note in notes:
                print(f"nfwserver: {note}", file=sys.stderr)
                log.info(note)
            stop = threading.Event()
            for sig in (signal.SIGINT, signal.SIGTERM):
                try:
                    signal.signal(sig, lambda *_: stop.set())
                except ValueError:  # not the main thread (embedded use)
                    pass
            stop.wait(args.duration)
    finally:
        station.stop()
        log.info("stopped")
        if file_handler is not None:
            logging.getLogger().removeHandler(file_handler)
            file_handler.close()
    return 0
