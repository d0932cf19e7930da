"""One sentence for a listener that cannot bind: which port, which setting, what to do.

Every listener of the station (Nova's TCP server, PREDICT's UDP server, the web dashboard) binds in its
``start()`` (through :mod:`nfwserver.listen_socket`) and turns the ``OSError`` of ``bind`` into
:func:`bind_failure`'s, so ``nfwserver run`` says ``cannot start the station: port 8090 is already in use (by
another program or another station); set [tcp] port to another port`` rather than ``[Errno 98] Address already
in use``.  On Windows a port another socket holds with ``SO_EXCLUSIVEADDRUSE`` (as ours do) fails with
WSAEACCES, not WSAEADDRINUSE, so there an access error is read as "in use" too (it can also be a port range
Windows reserves, which the sentence mentions); on POSIX it means a port below 1024 without privileges.  The
result is still an :class:`OSError` with the same ``errno`` (callers that handle OSError keep working); its
``strerror`` is the sentence.
"""

from __future__ import annotations

import errno
import sys

#: ``errno`` values of a port in use: POSIX's, and Windows sockets' own numbers (WSAEADDRINUSE).
_IN_USE = frozenset({errno.EADDRINUSE, getattr(errno, "WSAEADDRINUSE", errno.EADDRINUSE)})
_ACCESS = frozenset({errno.EACCES, getattr(errno, "WSAEACCES", errno.EACCES)})
_NOT_HERE = frozenset({errno.EADDRNOTAVAIL, errno.EAFNOSUPPORT,
                       getattr(errno, "WSAEADDRNOTAVAIL", errno.EADDRNOTAVAIL),
                       getattr(errno, "WSAEAFNOSUPPORT", errno.EAFNOSUPPORT)})


def bind_failure(exc: OSError, section: str, host: str, port: int, *, host_key: str = "host",
                 port_key: str = "port", what: str = "") -> OSError:
    """The error to raise when binding ``host``:``port`` (configured as ``[section] host_key/port_key``) failed
    with ``exc``; ``what`` names the listener (e.g. "PREDICT UDP") in the sentence when given."""
    port_setting = f"[{section}] {port_key}"
    host_setting = f"[{section}] {host_key}"
    who = f"{what} " if what else ""
    in_use = f"{who}port {port} is already in use (by another program or another station)"
    if exc.errno in _IN_USE:
        text = f"{in_use}; set {port_setting} to another port"
    elif exc.errno in _ACCESS and sys.platform == "win32":
        text = f"{in_use}, or in a range Windows reserves; set {port_setting} to another port"
    elif exc.errno in _ACCESS:
        text = (f"{who}{port_setting} {port} may not be used by this user (ports below 1024 need privileges; "
                f"set {port_setting})")
    elif exc.errno in _NOT_HERE:
        text = f"{who}{host_setting} {host} is not an address of this machine (set {host_setting})"
    else:
        reason = exc.strerror or str(exc) or type(exc).__name__
        text = f"{who}cannot listen on {host} port {port} ({host_setting}, {port_setting}): {reason}"
    return OSError(exc.errno, text)
