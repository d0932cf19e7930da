"""``nfwserver elements``: update, list and prune the stored catalog (InstantTrack UPDATE, OLD, CRASH), and list
the named sources (:mod:`nfwserver.config.element_presets`).

Every action works on the store ``nfwserver run`` reads: ``--store FILE`` if given, else
``[elements] store`` of the configuration (``--config FILE``, else the user's file, else the user
data directory).  Data on stdout, one sentence per problem on stderr, progress on stderr.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from datetime import datetime, timezone
from typing import TYPE_CHECKING

from nfwserver.cli.arguments import element_source_value, number_in
from nfwserver.cli.errors import CliError, load_config_or_fail, say
from nfwserver.cli.tracking_options import config_file
from nfwserver.config.element_presets import DEFAULT_PRESET, PRESETS

if TYPE_CHECKING:
    from nfwserver.app.element_store import ElementStore
    from nfwserver.config.schema import Config


def register(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = subparsers.add_parser("elements", help="update, list or prune the stored element catalog",
                              description="Manage the stored element catalog (InstantTrack UPDATE, OLD and CRASH).")
    sub = p.add_subparsers(dest="elements_action", metavar="ACTION", required=True)
    up = sub.add_parser("update", help="merge named sources, element files or URLs into the stored catalog "
                        "(newer epochs only)")
    up.add_argument("sources", nargs="*", type=element_source_value, metavar="NAME|FILE|URL",
                    help="named sources (`nfwserver elements sources`), element files or http(s) URLs (default: "
                    f"[elements] files, urls and sources of the configuration, else the {DEFAULT_PRESET} source)")
    up.add_argument("--timeout", type=number_in(0, 3600, low_open=True, unit="s"), default=20.0,
                    metavar="SECONDS", help="seconds for each URL's whole download (default 20)")
    up.set_defaults(func=run_update)
    ls = sub.add_parser("list", help="list the catalog the station uses (stored + files + bundled)")
    ls.set_defaults(func=run_list)
    src = sub.add_parser("sources", help="list the named sources (CelesTrak groups, AMSAT) and their URLs")
    src.set_defaults(func=run_sources)
    pr = sub.add_parser("prune", help="remove decayed objects and old sets from the stored catalog",
                        description="InstantTrack's CRASH and OLD: remove objects that have decayed and sets whose "
                        "epoch is more than --days before now; the store is rewritten atomically.  The selected "
                        "satellite (saved state and [server] satellite) and [satellites] favourites are never "
                        "removed; the store is never emptied without --all; removing more than half asks first "
                        "on a terminal (--yes: do not ask; without a terminal --yes is required).")
    pr.add_argument("--days", type=number_in(0, 36600, low_open=True, unit="days"), default=30.0,
                    help="remove sets older than this many days (default 30)")
    pr.add_argument("--dry-run", action="store_true", help="list what would be removed; change nothing")
    pr.add_argument("--all", action="store_true", help="allow removing every set (the store may end up empty)")
    pr.add_argument("--yes", action="store_true", help="remove more than half without asking")
    pr.set_defaults(func=run_prune)
    for action in (up, ls, pr, src):
        action.add_argument("--store", metavar="FILE", help="stored catalog file (default: [elements] store)")
        action.add_argument("--config", metavar="FILE", help="configuration file (default: the user's)")


def _config(args: argparse.Namespace) -> Config:

    config = load_config_or_fail(args.config)
    if args.store:
        config = dataclasses.replace(config, elements=dataclasses.replace(config.elements, store=args.store))
    return config


def _store(config: Config) -> ElementStore:
    from nfwserver.app.station_catalog import configured_store

    store = configured_store(config)
    if store is None:
        raise CliError(f'no stored catalog: [elements] store is "none" in {config_file(config)}; give --store FILE')
    return store



def run_update(args: argparse.Namespace) -> int:
    from rich.console import Console
    from rich.progress import BarColumn, DownloadColumn, Progress, TaskID, TextColumn

    from nfwserver.app.element_sources import SourceError, SourceLimits, read_source

    config = _config(args)
    store = _store(config)
    labels = _sources(args.sources, config)
    sources = list(labels)
    limits = SourceLimits.of(config.elements.max_source_mib, config.elements.max_source_sets)
    sets, rejected, failed = [], [], []
    columns = (TextColumn("{task.description}"), BarColumn(), DownloadColumn(), TextColumn("{task.fields[sets]} sets"))
    console = Console(stderr=True)
    with Progress(*columns, console=console, transient=True, disable=not console.is_terminal) as progress:
        for source in sources:
            task = progress.add_task((labels[source] or source)[-40:], total=None, sets=0)

            def moved(done: int, total: int | None, task: TaskID = task) -> None:
                progress.update(task, completed=done, total=total)

            try:
                loaded = read_source(source, args.timeout, moved, limits)
            except SourceError as exc:
                failed.append(f"{labels[source]}: {exc}" if labels[source] else str(exc))
                progress.remove_task(task)
                continue
            progress.update(task, sets=len(loaded.sets))
            sets += loaded.sets
            rejected += loaded.rejected
    for message in failed:
        say(message)
    for r in rejected:
        say(f"rejected: {r}")
    if not sets:  # every source failed, and each has been reported; the store is as it was
        if store.path.exists():
            say(f"the stored catalog {store.path} is unchanged")
        return 1
    try:
        catalog, summary = store.update(sets)
    except OSError as exc:
        raise CliError(f"cannot write {store.path}: {exc.strerror or exc}") from None
    print(f"{len(sets)} sets read from {len(sources) - len(failed)} of {len(sources)} source(s); "
          f"stored catalog {store.path}: {len(catalog)} satellites")
    print(f"added {len(summary.added)}, updated {len(summary.updated)}, not newer {len(summary.not_newer)}, "
          f"rejected {len(rejected)}")
    return 1 if failed else 0


def _sources(given: list[str], config: Config) -> dict[str, str]:
    """The sources to read, each mapped to its label (a preset's, or ``""``): the ones given (preset names
    become their URLs), else the configured ones, else the default preset (said on stderr)."""
    from nfwserver.app.station_catalog import configured_urls
    from nfwserver.config.element_presets import preset_urls

    mirror = config.elements.preset_mirror
    if given:
        out: dict[str, str] = {}
        for source in given:
            out.update(preset_urls([source], mirror) if source in PRESETS else {source: ""})
        return out
    configured = {**dict.fromkeys(config.elements.files, ""), **configured_urls(config.elements)}
    if configured:
        return configured
    say(f"no element sources configured ([elements] sources, files or urls in {config_file(config)}): "
         f"using the {PRESETS[DEFAULT_PRESET].label} source")
    return preset_urls([DEFAULT_PRESET], mirror)


def run_sources(args: argparse.Namespace) -> int:
    """The named sources, one a line: name, provider, form, what, URL; configured ones marked."""
    config = _config(args)
    chosen = set(config.elements.sources)
    rows = [f"{'':1} {'name':20}  {'provider':9}  {'form':8}  {'holds':52}  url\n"]
    for preset in PRESETS.values():
        mark = "*" if preset.name in chosen else " "
        rows.append(f"{mark} {preset.name:20}  {preset.provider:9}  {preset.form:8}  {preset.what:52}  "
                    f"{preset.url(config.elements.preset_mirror)}\n")
    try:
        sys.stdout.write("".join(rows))
        sys.stdout.flush()
    except BrokenPipeError:
        sys.stderr.close()
        return 0
    where = ", ".join(config.elements.sources) or "none"
    say(f"* = in [elements] sources of {config_file(config)} ({where}); `nfwserver elements update NAME` "
         "fetches one now")
    return 0


def run_list(args: argparse.Namespace) -> int:
    from nfwserver.app.element_sources import BUNDLED_SOURCE
    from nfwserver.app.station_catalog import configured_store, load_station_catalog

    config = _config(args)
    store = configured_store(config)
    catalog, fetched = load_station_catalog(config)
    for problem in fetched.failed:
        say(f"element source unavailable: {problem}")
    now = datetime.now(timezone.utc)
    stored_source = str(store.path) if store is not None else None
    counts = {"stored": 0, "bundled": 0, "file": 0}
    lines = [f"{'catalog':>7}  {'dde name':12}  {'age d':>6}  {'source':7}  name\n"]
    for sat in catalog:
        source = sat.elements.source
        kind = "stored" if source == stored_source else "bundled" if source == BUNDLED_SOURCE else "file"
        counts[kind] += 1
        lines.append(f"{sat.catalog_number:>7}  {sat.dde_name:12}  {sat.age_days(now):6.1f}  {kind:7}  {sat.name}\n")
    try:
        sys.stdout.write("".join(lines))
        sys.stdout.flush()
    except BrokenPipeError:  # the reader went away (e.g. piped into head)
        sys.stderr.close()
        return 0
    where = f"stored catalog {store.path}" if store is not None else 'no stored catalog ([elements] store = "none")'
    say(f"{len(catalog)} satellites: {counts['stored']} from the {where}, {counts['file']} from [elements] files, "
         f"{counts['bundled']} from the bundled set")
    if counts["bundled"]:
        say(f"the bundled element set is in use ([elements] use_bundled = false in {config_file(config)} "
             "turns it off); `nfwserver elements update FILE|URL` stores current sets")
    return 0


def _protected(config: Config) -> dict[int, str]:
    """Catalog numbers prune keeps, with why: the selected satellite (saved state, [server] satellite) and
    the favourites."""
    from nfwserver.app.session_state import StateFile

    keep: dict[int, str] = {n: "a favourite" for n in config.favourites}
    configured = config.server.satellite
    if isinstance(configured, str):  # a name, as SAT= takes it: the stored sets it names
        from nfwserver.tracking.catalog import Catalog

        named = Catalog(_store(config).load()).named(configured)
        configured = named[0].catalog_number if len(named) == 1 else None
    if configured is not None:
        keep[configured] = "the configured satellite"
    if config.state_file:
        saved = StateFile(None if config.state_file == "default" else config.state_file).load().satellite
        if saved is not None:
            keep[saved] = "the selected satellite"
    return keep


def _confirm(question: str) -> bool:
    print(f"{question} [y/N] ", end="", file=sys.stderr, flush=True)
    try:
        return sys.stdin.readline().strip().lower() in ("y", "yes")
    except (OSError, KeyboardInterrupt):
        return False


def run_prune(args: argparse.Namespace) -> int:

    config = _config(args)
    store = _store(config)
    if not store.path.exists():
        raise CliError(f"the stored catalog {store.path} does not exist yet (`nfwserver elements update` creates it)")
    keep = _protected(config)
    plan = store.plan_prune(datetime.now(timezone.utc), args.days, frozenset(keep))
    for es in plan.protected:
        say(f"kept {es.catalog_number} {es.name}: {keep[es.catalog_number]}")
    removed = plan.removed
    if args.dry_run:
        for es in removed:
            reason = "decayed" if es in plan.decayed else f"{(datetime.now(timezone.utc) - es.epoch).days} days old"
            print(f"{es.catalog_number:>7}  {es.name}  ({reason})")
        print(f"would remove {len(plan.decayed)} decayed and {len(plan.old)} older than {args.days:g} days; "
              f"{plan.kept} of {plan.total} sets would remain in {store.path}")
        return 0
    if removed and not plan.kept and not args.all:
        raise CliError(f"pruning would empty {store.path} (all {plan.total} sets are decayed or older than "
                       f"{args.days:g} days); `nfwserver elements update` fetches current ones, --all removes them "
                       "anyway, --dry-run lists them")
    if 2 * len(removed) > plan.total and not args.yes:
        what = f"{len(removed)} of the {plan.total} sets in {store.path}"
        if not sys.stdin.isatty():
            raise CliError(f"pruning would remove {what}; give --yes to confirm (--dry-run lists them)")
        if not _confirm(f"remove {what}?"):
            say("nothing removed")
            return 1
    try:
        kept = store.apply_prune(plan)
    except OSError as exc:
        raise CliError(f"cannot write {store.path}: {exc.strerror or exc}") from None
    for es in plan.decayed:
        say(f"removed {es.catalog_number} {es.name}: decayed")
    print(f"removed {len(plan.decayed)} decayed and {len(plan.old)} older than {args.days:g} days; "
          f"{kept} sets remain in {store.path}")
    return 0
