"""One sentence for a listener that cannot bind: which port, which setting, what to do.

Every listener of the station (Nova's TCP server, PREDICT's UDP server, the web dashboard) binds in its
``start()`` and turns the ``OSError`` of ``bind`` into :func:`bind_failure`'s, so ``nfwserver run`` says
``cannot start the station: [tcp] port 8090 is in use (another nfwserver? set [tcp] port)`` rather than
``[Errno 98] Address already in use``.  The result is still an :class:`OSError` with the same ``errno``
(callers that handle OSError keep working); its ``strerror`` is the sentence.
"""

from __future__ import annotations

import errno


def bind_failure(exc: OSError, section: str, host: str, port: int, *, host_key: str = "host",
                 port_key: str = "port", what: str = "") -> OSError:
    """The error to raise when binding ``host``:``port`` (configured as ``[section] host_key/port_key``) failed
    with ``exc``; ``what`` names the listener (e.g. "PREDICT UDP") in the sentence when given."""
    port_setting = f"[{section}] {port_key}"
    host_setting = f"[{section}] {host_key}"
    who = f"{what} " if what else ""
    if exc.errno == errno.EADDRINUSE:
        text = f"{who}{port_setting} {port} is in use (another nfwserver? set {port_setting})"
    elif exc.errno == errno.EACCES:
        text = (f"{who}{port_setting} {port} may not be used by this user (ports below 1024 need privileges; "
                f"set {port_setting})")
    elif exc.errno in (errno.EADDRNOTAVAIL, errno.EAFNOSUPPORT):
        text = f"{who}{host_setting} {host} is not an address of this machine (set {host_setting})"
    else:
        reason = exc.strerror or str(exc) or type(exc).__name__
        text = f"{who}cannot listen on {host} port {port} ({host_setting}, {port_setting}): {reason}"
    return OSError(exc.errno, text)
