"""Reading element sets from the bundled file, local files and URLs (InstantTrack UPDATE semantics).

URLs are read with a deadline for the whole transfer (and each read), redirects followed only to http(s)
(:mod:`nfwserver.app.http_fetch`).  Every file and URL is held to :class:`SourceLimits` (``[elements]
max_source_mib`` and ``max_source_sets``): a file is measured before it is read and read with a
bounded read, a download stops at the limit, and a source over either limit is refused whole with one
sentence naming it and the limit.  A source that fails is reported once, as one plain sentence
(:class:`SourceError`), and the others still load, so a dead web site never stops the server.  A
source that holds no element set at all (empty, binary or unrelated text) counts as failed: it is
almost always the wrong file or an error page.
"""

from __future__ import annotations

import contextlib
import re
import threading
from collections.abc import Callable, Mapping
from contextlib import AbstractContextManager
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from nfwserver.config.files import FileRefused, FileTooLarge, read_regular_bytes
from nfwserver.tracking.elements import ElementSet, LoadResult, Rejection, load_elements

if TYPE_CHECKING:
    from nfwserver.clock import Clock

BUNDLED = "amateur.txt"
BUNDLED_SOURCE = f"bundled {BUNDLED}"
_CHUNK = 64 * 1024

#: ``progress(bytes_so_far, total_bytes_or_None)`` during a download.
ProgressCallback = Callable[[int, "int | None"], None]


class SourceError(Exception):
    """A source that yielded nothing usable; ``str()`` is one sentence naming the source."""


@dataclass(frozen=True)
class SourceLimits:
    """What one element source (a file or a URL) may hold; the defaults are the configuration's."""

    max_bytes: int = 64 * 2**20  #: size of the file or download, bytes (``[elements] max_source_mib``)
    max_sets: int = 100_000  #: element sets in it (``[elements] max_source_sets``)

    @classmethod
    def of(cls, max_source_mib: float, max_source_sets: int) -> SourceLimits:
        """The limits ``[elements] max_source_mib`` (MiB) and ``max_source_sets`` set."""
        return cls(int(max_source_mib * 2**20), max_source_sets)

    def too_large(self, source: str) -> SourceError:
        size = f"{self.max_bytes / 2**20:g} MiB" if self.max_bytes >= 2**20 else f"{self.max_bytes:,} bytes"
        return SourceError(f"{source} is larger than {size}, the limit for one element source "
                           "([elements] max_source_mib)")

    def too_many(self, source: str) -> SourceError:
        return SourceError(f"{source} holds more than {self.max_sets:,} element sets, the limit for one element "
                           "source ([elements] max_source_sets)")


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
    from importlib import resources  # here: it brings zipfile, which a command reading a file never needs

    text = resources.files("nfwserver.data").joinpath(BUNDLED).read_bytes()
    loaded = load_elements(text, source=BUNDLED_SOURCE)
    return FetchResult(loaded.sets, loaded.rejected, bundled=len(loaded.sets))


def _network_reason(exc: BaseException, timeout_s: float) -> str:
    import socket
    import urllib.error

    from nfwserver.app.http_fetch import RedirectRefused

    if isinstance(exc, urllib.error.HTTPError):
        if 300 <= exc.code < 400:  # urllib's loop message is three lines; one is enough
            return f"too many redirects (HTTP {exc.code}; a redirect loop?)"
        return " ".join(f"the server answered HTTP {exc.code} {exc.reason}".split())
    if isinstance(exc, RedirectRefused):
        return str(exc.reason)
    if isinstance(exc, urllib.error.URLError):
        exc = exc.reason if isinstance(exc.reason, BaseException) else OSError(str(exc.reason))
    if isinstance(exc, (socket.timeout, TimeoutError)):
        return f"no answer within {timeout_s:g} s"
    if isinstance(exc, socket.gaierror):
        return "the host name is unknown"
    if isinstance(exc, OSError) and exc.strerror:
        return exc.strerror[0].lower() + exc.strerror[1:]
    return repr(str(exc) or type(exc).__name__)[1:-1]  # one line, whatever the server sent


def fetch_url(url: str, timeout_s: float = 20.0, progress: ProgressCallback | None = None,
              limits: SourceLimits = SourceLimits(), cancel: threading.Event | None = None,
              clock: Clock | None = None) -> bytes:
    """GET ``url`` (http/https only, redirects too), at most ``limits.max_bytes``, the whole transfer (connect
    included) within ``timeout_s`` seconds of ``clock`` (the system's unless given); ``cancel`` set aborts it
    at once.  Raises :class:`SourceError` (one sentence)."""
    scheme = url.partition("://")[0].lower()
    if scheme not in ("http", "https"):
        raise SourceError(f"{url}: unsupported scheme {scheme}:// (element sources are files or http(s) URLs)")
    import http.client  # the network modules (and ssl) load only when a URL is fetched: 3 MiB for `passes`
    import urllib.error

    from nfwserver.app.http_fetch import Deadline, open_url

    chunks: list[bytes] = []
    size = 0
    deadline = Deadline(timeout_s, cancel, clock).start()
    try:
        with open_url(url, timeout_s, deadline) as response:
            length = response.headers.get("Content-Length")
            total = int(length) if length and length.isascii() and length.isdigit() else None
            if total is not None and total > limits.max_bytes:
                raise limits.too_large(url)
            while size <= limits.max_bytes and not deadline.expired:
                chunk = response.read1(_CHUNK)  # what has arrived: a trickle cannot hold one read for long
                if not chunk:
                    break
                chunks.append(chunk)
                size += len(chunk)
                if progress is not None:
                    progress(size, total)
            if deadline.expired:
                raise TimeoutError
            if total is not None and size < total:
                raise OSError(f"the connection closed {total - size} bytes before the announced end")
    except (OSError, ValueError, urllib.error.URLError, http.client.HTTPException) as exc:
        if deadline.expired:
            why = "stopped: the station is stopping" if deadline.cancelled else \
                f"the whole transfer did not end within {timeout_s:g} s"
            raise SourceError(f"cannot fetch {url}: {why}") from None
        raise SourceError(f"cannot fetch {url}: {_network_reason(exc, timeout_s)}") from None
    finally:
        deadline.finish()
    if size > limits.max_bytes:
        raise limits.too_large(url)
    return b"".join(chunks)


def read_file(path: str, limits: SourceLimits = SourceLimits()) -> bytes:
    """The bytes of the regular file ``path``, refused unread when its size is over ``limits.max_bytes`` and
    read with a bounded read (a file that grows past the limit is refused).  Anything but a regular file (a
    FIFO, whose open would wait for a writer for ever; a device such as /dev/zero) is refused at once."""
    try:
        return read_regular_bytes(path, limits.max_bytes)
    except FileTooLarge:
        raise limits.too_large(path) from None
    except FileRefused:
        raise SourceError(f"cannot read {path}: it is not a regular file") from None
    except OSError as exc:
        raise SourceError(f"cannot read {path}: {(exc.strerror or str(exc)).lower()}") from None


#: What text of element sets does not hold: undecodable bytes, control characters other than tab, line feed,
#: carriage return and form feed, and DEL.
_ODD = re.compile("[\x00-\x08\x0b\x0e-\x1f\x7f\ufffd]")


def _looks_binary(data: bytes) -> bool:
    """NUL bytes, or text that is mostly not UTF-8 or full of control characters."""
    head = data[:65536]
    if b"\0" in head:
        return True
    text = head.decode("utf-8", errors="replace")
    return len(_ODD.findall(text)) > len(text) // 20


def _fewest_sets(data: bytes) -> int:
    """A lower bound of the sets in ``data``, counted without parsing: TLE line 1s or OMM JSON objects."""
    return max(data.count(b"\n1 ") + data.startswith(b"1 "), data.count(b'"NORAD_CAT_ID"'))


def parse_source(data: bytes, source: str, limits: SourceLimits = SourceLimits()) -> LoadResult:
    """The element sets in ``data``; raises :class:`SourceError` when there are none or too many."""
    if not data.strip():
        raise SourceError(f"{source} is empty")
    if _looks_binary(data):
        raise SourceError(f"{source} is not a text file of element sets (it holds binary data)")
    if _fewest_sets(data) > limits.max_sets:
        raise limits.too_many(source)
    loaded = load_elements(data, source=source)
    if len(loaded.sets) > limits.max_sets:
        raise limits.too_many(source)
    if not loaded.sets:
        first = loaded.rejected[0] if loaded.rejected else None
        at = f"line {first.line_number}: " if first is not None and first.line_number > 0 else ""
        why = f" (first problem: {at}{first.reason})" if first is not None else ""
        raise SourceError(f"{source} holds no element sets{why}")
    return loaded


def read_source(source: str, timeout_s: float = 20.0, progress: ProgressCallback | None = None,
                limits: SourceLimits = SourceLimits(),
                parsing: Callable[[], AbstractContextManager[object]] = contextlib.nullcontext,
                cancel: threading.Event | None = None) -> LoadResult:
    """Element sets from a file or an http(s) URL; raises :class:`SourceError` (one sentence).

    ``parsing()`` is entered around the parse (not the download): the station passes
    :func:`~nfwserver.app.long_lived.building_long_lived`."""
    if is_url(source):
        data = fetch_url(source, timeout_s, progress, limits, cancel)
    else:
        data = read_file(source, limits)
        if progress is not None:
            progress(len(data), len(data))
    with parsing():
        return parse_source(data, source, limits)


def fetch_all(files: tuple[str, ...] = (), urls: tuple[str, ...] = (), use_bundled: bool = True,
              timeout_s: float = 20.0, limits: SourceLimits = SourceLimits(),
              parsing: Callable[[], AbstractContextManager[object]] = contextlib.nullcontext,
              labels: Mapping[str, str] | None = None, cancel: threading.Event | None = None) -> FetchResult:
    """Element sets from every source, in order; never raises (failures are in ``failed``, each one line
    opening with the source's label from ``labels`` when it has one, e.g. a preset's name)."""
    result = bundled_elements() if use_bundled else FetchResult()
    for source in (*files, *urls):
        try:
            loaded = read_source(source, timeout_s, limits=limits, parsing=parsing, cancel=cancel)
        except SourceError as exc:
            label = (labels or {}).get(source)
            result.failed.append(f"{label}: {exc}" if label else str(exc))
            continue
        result.sets += loaded.sets
        result.rejected += loaded.rejected
    return result
