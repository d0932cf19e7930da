"""HTTP on Nova's TCP port: a web page's request, closed before anything in it runs (cross-protocol scripting).

Any web page the operator visits may ``fetch('http://127.0.0.1:8090/', {method: 'POST', mode: 'no-cors',
body: '\\r\\nSAT=27607\\r\\nTRACK ON\\r\\n'})``: the browser sends a request line, its headers, a blank line and
the body, and without this check the body's lines would run as commands.  A browser's request always starts
with its request line (``METHOD /path HTTP/1.1``; a page cannot put a CR, LF or NUL in the method or the URL)
and always carries ``Host:``, so the first line of such a connection is recognised and the connection closed
at once, nothing after it run (as Redis closes a connection whose command is ``POST`` or ``Host:``).

:func:`http_line` recognises a request line, or a header line of a request (a name browsers or HTTP clients
send, or ``Sec-*``), at any point of a connection: no Nova command has either form.  The server
(:mod:`nfwserver.tcp.server`) looks at every line of a read before running any of them.
"""

from __future__ import annotations

import re
from collections.abc import Iterable

__all__ = ["http_in", "http_line"]

#: ``METHOD request-target HTTP/x.y`` (RFC 9112 section 3): a token, one target, the version.
_REQUEST_LINE = re.compile(rb"[!#$%&'*+.^_`|~0-9A-Za-z-]+[ \t]+\S+[ \t]+HTTP/\d(\.\d)?[ \t]*", re.IGNORECASE)
#: ``name:`` at the start of a line (a header field name is a token).
_HEADER = re.compile(rb"([!#$%&'*+.^_`|~0-9A-Za-z-]+)[ \t]*:")
#: Request header names (lower case): every browser request carries some of these.
_REQUEST_HEADERS = frozenset({
    b"host", b"origin", b"referer", b"user-agent", b"content-type", b"content-length", b"transfer-encoding",
    b"accept", b"accept-encoding", b"accept-language", b"accept-charset", b"connection", b"keep-alive",
    b"cookie", b"authorization", b"cache-control", b"pragma", b"upgrade", b"upgrade-insecure-requests",
    b"expect", b"te", b"dnt", b"priority", b"range", b"if-modified-since", b"if-none-match",
    b"proxy-connection", b"proxy-authorization", b"forwarded", b"via", b"x-forwarded-for", b"x-requested-with",
})


def http_line(line: bytes) -> str | None:
    """What ``line`` (one line, without its terminator) is when it is HTTP: "an HTTP request line" or "an HTTP
    header line"; None when it is not."""
    text = line.strip(b" \t")
    if _REQUEST_LINE.fullmatch(text):
        return "an HTTP request line"
    header = _HEADER.match(text)
    if header is not None:
        name = header.group(1).lower()
        if name in _REQUEST_HEADERS or name.startswith(b"sec-"):
            return "an HTTP header line"
    return None


def http_in(lines: Iterable[bytes | None]) -> str | None:
    """What the first HTTP line among ``lines`` is (see :func:`http_line`; None stands for an over-long line,
    which is not looked at); None when there is none."""
    return next((kind for line in lines if line is not None and (kind := http_line(line)) is not None), None)
