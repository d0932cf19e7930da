"""The station's satellite catalog, built from a Config exactly as ``nfwserver run`` builds it.

Order (InstantTrack UPDATE semantics, a set replaces another only with a newer epoch): the stored
catalog (``[elements] store``, kept by ``nfwserver elements update``) first, then the configured
element files, the configured URLs (only when asked: the command-line tools do not touch the
network unless told to), and the bundled set when ``[elements] use_bundled`` is on.  DDE names
follow ``[satellites] names``.
"""

from __future__ import annotations

from nfwserver.app.element_sources import FetchResult, fetch_all
from nfwserver.app.element_store import ElementStore
from nfwserver.config.schema import Config
from nfwserver.tracking.catalog import Catalog


def configured_store(config: Config) -> ElementStore | None:
    """The stored catalog ``config`` names (``"default"``: the user data directory), or None when off."""
    store = config.elements.store
    if not store:
        return None
    return ElementStore(None if store == "default" else store)


def load_station_catalog(config: Config, *, fetch_urls: bool = False,
                         timeout_s: float = 20.0) -> tuple[Catalog, FetchResult]:
    """The catalog ``nfwserver run`` tracks, and what reading the sources found.

    ``FetchResult.sets`` holds the sets read from files, URLs and the bundled file (not the
    stored ones); ``failed`` one sentence per source that could not be used.  Never raises for
    bad sources.
    """
    elements = config.elements
    store = configured_store(config)
    stored = store.load() if store is not None else []
    fetched = fetch_all(elements.files, elements.urls if fetch_urls else (), elements.use_bundled, timeout_s)
    catalog = Catalog(stored, dde_names=config.dde_names)
    catalog.update(fetched.sets)
    return catalog, fetched
