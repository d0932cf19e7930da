"""Fetching element sets from the bundled file, local files and URLs (InstantTrack UPDATE semantics).

URLs are read with a timeout and a size limit; a source that fails is reported and the others
still load, so a dead web site never stops the server.
"""

from __future__ import annotations

import http.client
import logging
import urllib.error
import urllib.request
from dataclasses import dataclass, field
from importlib import resources

from nfwserver.tracking.elements import ElementSet, Rejection, load_element_file, load_elements

log = logging.getLogger(__name__)

MAX_DOWNLOAD_BYTES = 50 * 1024 * 1024
BUNDLED = "amateur.txt"


@dataclass
class FetchResult:
    sets: list[ElementSet] = field(default_factory=list)
    rejected: list[Rejection] = field(default_factory=list)
    failed: list[str] = field(default_factory=list)  #: sources that could not be read at all


def bundled_elements() -> FetchResult:
    """The element sets shipped with nfwserver (popular amateur and weather satellites)."""
    text = resources.files("nfwserver.data").joinpath(BUNDLED).read_bytes()
    loaded = load_elements(text, source=f"bundled {BUNDLED}")
    return FetchResult(loaded.sets, loaded.rejected)


def fetch_url(url: str, timeout_s: float = 20.0) -> bytes:
    """GET ``url`` (http/https only); raises OSError/ValueError (or, for a broken HTTP reply,
    ``http.client.HTTPException``) with a clear message."""
    if not url.lower().startswith(("http://", "https://")):
        raise ValueError(f"{url!r} is not an http(s) URL")
    request = urllib.request.Request(url, headers={"User-Agent": "nfwserver"})
    with urllib.request.urlopen(request, timeout=timeout_s) as response:  # noqa: S310 - scheme checked above
        data = response.read(MAX_DOWNLOAD_BYTES + 1)
        missing = getattr(response, "length", None)
    if len(data) <= MAX_DOWNLOAD_BYTES and missing:
        raise OSError(f"the connection closed {missing} bytes before the announced end")
    if len(data) > MAX_DOWNLOAD_BYTES:
        raise ValueError(f"{url} is larger than {MAX_DOWNLOAD_BYTES // 2**20} MiB")
    return data


def fetch_all(files: tuple[str, ...] = (), urls: tuple[str, ...] = (), use_bundled: bool = True,
              timeout_s: float = 20.0) -> FetchResult:
    """Element sets from every source, in order; never raises."""
    result = bundled_elements() if use_bundled else FetchResult()
    for path in files:
        loaded = load_element_file(path)
        if loaded.rejected and not loaded.sets and loaded.rejected[0].line_number == 0:
            result.failed.append(f"{path}: {loaded.rejected[0].reason}")
        result.sets += loaded.sets
        result.rejected += loaded.rejected
    for url in urls:
        try:
            data = fetch_url(url, timeout_s)
        except (OSError, ValueError, urllib.error.URLError, http.client.HTTPException) as exc:
            why = repr(str(exc) or type(exc).__name__)[1:-1]  # one line, whatever the server sent
            result.failed.append(f"{url}: {why}")
            log.warning("cannot fetch elements from %s: %s", url, why)
            continue
        loaded = load_elements(data, source=url)
        result.sets += loaded.sets
        result.rejected += loaded.rejected
    return result
