"""Reading element sets from the bundled file, local files and URLs (InstantTrack UPDATE semantics).

URLs are read with a timeout and a size limit; a source that fails is reported once, as one
plain sentence (:class:`SourceError`), and the others still load, so a dead web site never stops
the server.  A source that holds no element set at all (empty, binary or unrelated text) counts
as failed: it is almost always the wrong file or an error page.
"""

from __future__ import annotations

import http.client
import socket
import urllib.error
import urllib.request
from collections.abc import Callable
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

from nfwserver.tracking.elements import ElementSet, LoadResult, Rejection, load_elements

MAX_DOWNLOAD_BYTES = 50 * 1024 * 1024
BUNDLED = "amateur.txt"
BUNDLED_SOURCE = f"bundled {BUNDLED}"
_CHUNK = 64 * 1024

#: ``progress(bytes_so_far, total_bytes_or_None)`` during a download.
ProgressCallback = Callable[[int, "int | None"], None]


class SourceError(Exception):
    """A source that yielded nothing usable; ``str()`` is one sentence naming the source."""


@dataclass
class FetchResult:
    sets: list[ElementSet] = field(default_factory=list)
    rejected: list[Rejection] = field(default_factory=list)
    failed: list[str] = field(default_factory=list)  #: one sentence per source that could not be used
    bundled: int = 0  #: how many of ``sets`` came from the bundled file


def is_url(source: str) -> bool:
    """True for anything with a scheme (``http://``, ``ftp://`` ...), which is not a file name."""
    scheme, sep, _ = source.partition("://")
    return bool(sep) and scheme.isalpha()


def bundled_elements() -> FetchResult:
    """The element sets shipped with nfwserver (popular amateur and weather satellites)."""
    text = resources.files("nfwserver.data").joinpath(BUNDLED).read_bytes()
    loaded = load_elements(text, source=BUNDLED_SOURCE)
    return FetchResult(loaded.sets, loaded.rejected, bundled=len(loaded.sets))


def _network_reason(exc: BaseException, timeout_s: float) -> str:
    if isinstance(exc, urllib.error.HTTPError):
        return f"the server answered HTTP {exc.code} {exc.reason}".rstrip()
    if isinstance(exc, urllib.error.URLError):
        exc = exc.reason if isinstance(exc.reason, BaseException) else OSError(str(exc.reason))
    if isinstance(exc, (socket.timeout, TimeoutError)):
        return f"no answer within {timeout_s:g} s"
    if isinstance(exc, socket.gaierror):
        return "the host name is unknown"
    if isinstance(exc, OSError) and exc.strerror:
        return exc.strerror[0].lower() + exc.strerror[1:]
    return repr(str(exc) or type(exc).__name__)[1:-1]  # one line, whatever the server sent


def fetch_url(url: str, timeout_s: float = 20.0, progress: ProgressCallback | None = None) -> bytes:
    """GET ``url`` (http/https only); raises :class:`SourceError` with one plain sentence."""
    scheme = url.partition("://")[0].lower()
    if scheme not in ("http", "https"):
        raise SourceError(f"{url}: unsupported scheme {scheme}:// (element sources are files or http(s) URLs)")
    request = urllib.request.Request(url, headers={"User-Agent": "nfwserver"})
    chunks: list[bytes] = []
    size = 0
    try:
        with urllib.request.urlopen(request, timeout=timeout_s) as response:  # noqa: S310 - scheme checked above
            length = response.headers.get("Content-Length")
            total = int(length) if length and length.isascii() and length.isdigit() else None
            while size <= MAX_DOWNLOAD_BYTES:
                chunk = response.read(_CHUNK)
                if not chunk:
                    break
                chunks.append(chunk)
                size += len(chunk)
                if progress is not None:
                    progress(size, total)
            if total is not None and size < total:
                raise OSError(f"the connection closed {total - size} bytes before the announced end")
    except (OSError, ValueError, urllib.error.URLError, http.client.HTTPException) as exc:
        raise SourceError(f"cannot fetch {url}: {_network_reason(exc, timeout_s)}") from None
    if size > MAX_DOWNLOAD_BYTES:
        raise SourceError(f"{url} is larger than {MAX_DOWNLOAD_BYTES // 2**20} MiB")
    return b"".join(chunks)


def _looks_binary(data: bytes) -> bool:
    """NUL bytes, or text that is mostly not UTF-8 or full of control characters."""
    head = data[:65536]
    if b"\0" in head:
        return True
    text = head.decode("utf-8", errors="replace")
    odd = sum(1 for c in text if c == "\ufffd" or (c < " " and c not in "\t\n\r\f") or c == "\x7f")
    return odd > len(text) // 20


def parse_source(data: bytes, source: str) -> LoadResult:
    """The element sets in ``data``; raises :class:`SourceError` when there are none."""
    if not data.strip():
        raise SourceError(f"{source} is empty")
    if _looks_binary(data):
        raise SourceError(f"{source} is not a text file of element sets (it holds binary data)")
    loaded = load_elements(data, source=source)
    if not loaded.sets:
        why = f" (first problem: line {loaded.rejected[0].line_number}: {loaded.rejected[0].reason})" \
            if loaded.rejected else ""
        raise SourceError(f"{source} holds no element sets{why}")
    return loaded


def read_source(source: str, timeout_s: float = 20.0, progress: ProgressCallback | None = None) -> LoadResult:
    """Element sets from a file or an http(s) URL; raises :class:`SourceError` (one sentence)."""
    if is_url(source):
        data = fetch_url(source, timeout_s, progress)
    else:
        try:
            data = Path(source).read_bytes()
        except OSError as exc:
            raise SourceError(f"cannot read {source}: {(exc.strerror or str(exc)).lower()}") from None
        if progress is not None:
            progress(len(data), len(data))
    return parse_source(data, source)


def fetch_all(files: tuple[str, ...] = (), urls: tuple[str, ...] = (), use_bundled: bool = True,
              timeout_s: float = 20.0) -> FetchResult:
    """Element sets from every source, in order; never raises (failures are in ``failed``)."""
    result = bundled_elements() if use_bundled else FetchResult()
    for source in (*files, *urls):
        try:
            loaded = read_source(source, timeout_s)
        except SourceError as exc:
            result.failed.append(str(exc))
            continue
        result.sets += loaded.sets
        result.rejected += loaded.rejected
    return result
