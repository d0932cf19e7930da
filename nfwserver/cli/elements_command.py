"""``nfwserver elements``: update the stored catalog from files and URLs, and list it."""

from __future__ import annotations

import argparse
import sys
from datetime import datetime, timezone


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser("elements", help="update or list the stored element catalog",
                              description="Manage the stored element catalog (InstantTrack UPDATE semantics).")
    sub = p.add_subparsers(dest="elements_action", metavar="ACTION", required=True)
    up = sub.add_parser("update", help="merge element files or URLs into the stored catalog (newer epochs only)")
    up.add_argument("sources", nargs="*", metavar="FILE|URL",
                    help="element files or http(s) URLs (default: the sources in the configuration)")
    up.add_argument("--store", metavar="FILE", help="stored catalog file (default: user data directory)")
    up.add_argument("--config", metavar="FILE", help="configuration file")
    up.add_argument("--timeout", type=float, default=20.0, metavar="SECONDS", help="per-URL timeout")
    up.set_defaults(func=run_update)
    ls = sub.add_parser("list", help="list the stored catalog")
    ls.add_argument("--store", metavar="FILE")
    ls.set_defaults(func=run_list)


def run_update(args: argparse.Namespace) -> int:
    from rich.progress import Progress

    from nfwserver.app.element_sources import fetch_all
    from nfwserver.app.element_store import ElementStore
    from nfwserver.cli import CliError
    from nfwserver.config import ConfigError, load_config

    sources = list(args.sources)
    if not sources:
        try:
            config = load_config(args.config)
        except ConfigError as exc:
            raise CliError(f"configuration refused: {exc}") from None
        sources = [*config.elements.files, *config.elements.urls]
        if not sources:
            raise CliError("no sources given and none configured ([elements] files or urls)")
    sets, rejected, failed = [], [], []
    with Progress(transient=True, console=None) as progress:
        task = progress.add_task("fetching elements", total=len(sources))
        for source in sources:
            is_url = source.lower().startswith(("http://", "https://"))
            result = fetch_all(urls=(source,) if is_url else (), files=() if is_url else (source,),
                               use_bundled=False, timeout_s=args.timeout)
            sets += result.sets
            rejected += result.rejected
            failed += result.failed
            progress.advance(task)
    store = ElementStore(args.store)
    try:
        catalog, summary = store.update(sets)
    except OSError as exc:
        raise CliError(f"cannot write {store.path}: {exc}") from None
    out = sys.stdout
    out.write(f"{len(sets)} sets read from {len(sources)} source(s); stored catalog {store.path}: {len(catalog)} "
              f"satellites\n")
    out.write(f"added {len(summary.added)}, updated {len(summary.updated)}, not newer {len(summary.not_newer)}, "
              f"rejected {len(rejected)}\n")
    for r in rejected:
        print(f"rejected: {r}", file=sys.stderr)
    for f in failed:
        print(f"unavailable: {f}", file=sys.stderr)
    return 1 if failed and not sets else 0


def run_list(args: argparse.Namespace) -> int:
    from nfwserver.app.element_store import ElementStore
    from nfwserver.tracking.catalog import Catalog

    store = ElementStore(args.store)
    catalog = Catalog(store.load())
    now = datetime.now(timezone.utc)
    print(f"{'catalog':>7}  {'dde name':12}  {'age d':>6}  name")
    for sat in catalog:
        print(f"{sat.catalog_number:>7}  {sat.dde_name:12}  {sat.age_days(now):6.1f}  {sat.name}")
    return 0
