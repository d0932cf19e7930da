"""Every listening socket of the station is made here: Nova's TCP server, the web dashboard, PREDICT's UDP port.

One rule per system, so that no other program (nor a second station) can share a port with ours:

- **Windows**: ``SO_EXCLUSIVEADDRUSE`` before ``bind``, and never ``SO_REUSEADDR``.  On Windows
  ``SO_REUSEADDR`` lets a socket bind a port another socket already holds (ours over theirs, or theirs over
  ours: a second station would silently take the first one's clients); ``SO_EXCLUSIVEADDRUSE`` forbids
  exactly that, and a bind over a port held that way fails with WSAEACCES rather than WSAEADDRINUSE
  (:mod:`nfwserver.listen_errors` reads both as "in use").
- **POSIX** (Linux, macOS): ``SO_REUSEADDR`` on a TCP listener.  There it only lets the listener bind while
  connections of an earlier listener on the same port linger in TIME_WAIT (a station restarted within a
  minute of its last client); it never lets two sockets listen on one port at once -- that needs
  ``SO_REUSEPORT``, which we never set -- so a busy port still fails with EADDRINUSE.  A UDP socket gets no
  option: on Linux ``SO_REUSEADDR`` *would* let two UDP sockets share a port.

:func:`claim_port` sets these options on a socket about to bind (the web dashboard's
:class:`http.server.ThreadingHTTPServer` makes its own socket and calls it from ``server_bind``);
:func:`stream_listener` and :func:`datagram_socket` make, claim and bind a socket in one call.
"""

from __future__ import annotations

import socket
import sys

__all__ = ["claim_port", "datagram_socket", "stream_listener"]


def claim_port(sock: socket.socket) -> None:
    """Set the options that keep ``sock``'s port ours alone (see the module docstring); before ``bind``."""
    if sys.platform == "win32":
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_EXCLUSIVEADDRUSE, 1)
    elif sock.type == socket.SOCK_STREAM:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)


def stream_listener(host: str, port: int, backlog: int = 64) -> socket.socket:
    """A non-blocking TCP socket listening on ``host``:``port`` (0: any free port); OSError when it cannot bind."""
    family, _, _, _, sockaddr = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)[0]
    listener = socket.socket(family, socket.SOCK_STREAM)
    try:
        claim_port(listener)
        listener.bind(sockaddr)
        listener.listen(backlog)
        listener.setblocking(False)
    except OSError:
        listener.close()
        raise
    return listener


def datagram_socket(host: str, port: int) -> socket.socket:
    """A UDP socket bound to ``host``:``port`` (IPv4); OSError when it cannot bind."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        claim_port(sock)
        sock.bind((host, port))
    except OSError:
        sock.close()
        raise
    return sock
