"""The station's satellite catalog, built from a Config exactly as ``nfwserver run`` builds it.

Order (InstantTrack UPDATE semantics, a set replaces another only with a newer epoch): the stored
catalog (``[elements] store``, kept by ``nfwserver elements update``) first, then the configured
element files, the configured URLs and named sources (only when asked: the command-line tools do not touch the
network unless told to), and the bundled set when ``[elements] use_bundled`` is on.  DDE names
follow ``[satellites] names``.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from contextlib import AbstractContextManager, nullcontext

from nfwserver.app.element_sources import FetchResult, SourceLimits, fetch_all
from nfwserver.app.element_store import ElementStore
from nfwserver.config.element_presets import preset_urls
from nfwserver.config.schema import Config, ElementsConfig
from nfwserver.tracking.catalog import Catalog


def configured_store(config: Config) -> ElementStore | None:
    """The stored catalog ``config`` names (``"default"``: the user data directory), or None when off."""
    store = config.elements.store
    if not store:
        return None
    return ElementStore(None if store == "default" else store)


def configured_urls(elements: ElementsConfig) -> dict[str, str]:
    """Every configured URL: ``[elements] urls`` (label ``""``) then the named sources' URLs (label: the
    preset, e.g. ``amateur (CelesTrak, TLE)``)."""
    return {**dict.fromkeys(elements.urls, ""), **preset_urls(elements.sources, elements.preset_mirror)}


def fetch_configured(elements: ElementsConfig, *, fetch_urls: bool, timeout_s: float = 20.0,
                     parsing: Callable[[], AbstractContextManager[object]] = nullcontext,
                     cancel: threading.Event | None = None) -> FetchResult:
    """The sets of every configured source (URLs and named sources only when ``fetch_urls``; ``cancel`` set
    aborts a download in progress)."""
    urls = configured_urls(elements) if fetch_urls else {}
    limits = SourceLimits.of(elements.max_source_mib, elements.max_source_sets)
    return fetch_all(elements.files, tuple(urls), elements.use_bundled, timeout_s, limits, parsing, labels=urls,
                     cancel=cancel)


def load_station_catalog(config: Config, *, fetch_urls: bool = False,
                         timeout_s: float = 20.0) -> tuple[Catalog, FetchResult]:
    """The catalog ``nfwserver run`` tracks, and what reading the sources found.

    ``FetchResult.sets`` holds the sets read from files, URLs and the bundled file (not the
    stored ones); ``failed`` one sentence per source that could not be used.  Never raises for
    bad sources.
    """
    store = configured_store(config)
    stored = store.load() if store is not None else []
    fetched = fetch_configured(config.elements, fetch_urls=fetch_urls, timeout_s=timeout_s)
    catalog = Catalog(stored, dde_names=config.dde_names)
    catalog.update(fetched.sets)
    return catalog, fetched
