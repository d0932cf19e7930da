"""Which requests the dashboard answers, judged from their headers: the browser it runs in is not trusted.

- **Host** (DNS rebinding): a page on ``evil.example`` whose name the attacker points at 127.0.0.1 may
  read the station as its own origin.  Only the names the station is reached by are answered: ``[web]
  host``, ``localhost``, any loopback address, the address the connection came in on, and the names in
  ``[web] hostnames``; anything else is refused (421).  A request without ``Host`` (HTTP/1.0 from a
  tool; every browser sends one) is answered.
- **Commands** (cross-site requests): ``POST /api/command`` is taken only as ``application/json``, a type
  no other site's page can send without a CORS preflight, which the station never grants; and when
  the browser says where the request comes from (``Sec-Fetch-Site``, ``Origin``, else ``Referer``), it
  must be the station's own page (``http://`` or, behind a TLS proxy, ``https://`` with the request's
  Host).  A request that says nothing of the kind (``curl``, a script) is no browser's and may carry the
  token like any other.
- **Event streams**: ``GET /api/stream`` holds a connection; one another site's page asks for (which it
  cannot read, but may keep open) is refused (403) when the browser says so (``Sec-Fetch-Site``), so such
  pages cannot take the station's own address's connections.
"""

from __future__ import annotations

import ipaddress
import re
from typing import Protocol

from nfwserver.config.schema import WebConfig

__all__ = ["cross_site_reason", "foreign_site_reason", "host_name", "host_refusal"]

_WILDCARDS = ("0.0.0.0", "::", "")
_HOST_FORM = re.compile(r"(?:\[(?P<bracketed>[^\[\]]*)\]|(?P<name>[^:\[\]]*))(?::[0-9]{1,5})?")


class Headers(Protocol):
    """A request's headers, looked up by name in any case (:class:`email.message.Message`)."""

    def get(self, name: str, default: None = None) -> str | None: ...


def host_name(header: str) -> str:
    """The name or address of a ``Host`` header, without its port, brackets, case or final dot.  Only
    ``name``, ``name:port`` and ``[address]:port`` (the port all digits) are taken apart: anything else
    (``localhost:8091.evil.example``, ``[::1].evil.example``) is returned whole, so it names no station."""
    host = header.strip().lower()
    form = _HOST_FORM.fullmatch(host)
    if form is None:
        return host
    return (form["bracketed"] if form["bracketed"] is not None else form["name"]).rstrip(".")


def _ip(text: str) -> ipaddress.IPv4Address | ipaddress.IPv6Address | None:
    try:
        ip = ipaddress.ip_address(text.split("%", 1)[0])
    except ValueError:
        return None
    if isinstance(ip, ipaddress.IPv6Address) and ip.ipv4_mapped is not None:
        return ip.ipv4_mapped
    return ip


def host_refusal(header: str | None, config: WebConfig, local_address: str) -> str | None:
    """Why a request with ``Host: header`` that arrived on ``local_address`` is refused, or None."""
    if header is None:
        return None  # HTTP/1.0 without Host: no browser sends that, so no page can have made it
    if not header.strip():
        return "an empty Host header"
    name = host_name(header)
    if name in ("localhost", *(n.lower().rstrip(".") for n in config.hostnames)):
        return None
    if config.host.lower() not in _WILDCARDS and name == config.host.lower().strip("[]"):
        return None
    ip = _ip(name)
    if ip is not None and (ip.is_loopback or ip == _ip(local_address)):
        return None
    return f"Host {name!r} is not a name of this station (add it to [web] hostnames)"


def foreign_site_reason(headers: Headers) -> str | None:
    """Why a request the browser says comes from another site's page (``Sec-Fetch-Site``) is refused, or None
    (the station's own page, a typed address or bookmark, or no browser)."""
    site = headers.get("Sec-Fetch-Site")
    if site is not None and site.strip().lower() not in ("same-origin", "none"):
        return f"a request from another site (Sec-Fetch-Site: {site.strip()[:40]})"
    return None


def cross_site_reason(headers: Headers, host: str) -> str | None:
    """Why a command request is refused as not coming from the station's own page, or None.

    ``headers`` are the request's (names in any case, as :class:`email.message.Message` gives them);
    ``host`` is its ``Host`` header, already accepted by :func:`host_refusal`."""
    media_type = (headers.get("Content-Type") or "").split(";", 1)[0].strip().lower()
    if media_type != "application/json":
        return "commands are taken only as application/json"
    why = foreign_site_reason(headers)
    if why is not None:
        return why
    own = tuple(f"{scheme}://{host.strip().lower()}" for scheme in ("http", "https"))  # https: behind a TLS proxy
    origin = headers.get("Origin")
    if origin is not None:
        return None if origin.strip().lower() in own else f"a request from another origin ({origin.strip()[:80]})"
    referer = headers.get("Referer")
    if referer is not None and not (referer.strip().lower() + "/").startswith(tuple(o + "/" for o in own)):
        return "a request from another page (Referer)"
    return None
