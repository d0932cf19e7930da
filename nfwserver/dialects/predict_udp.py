"""PREDICT's UDP socket server (default port 1210): datagrams in, replies to the sender's address and port.

The protocol itself is :mod:`nfwserver.dialects.predict_protocol`.  The server binds 127.0.0.1 unless
told otherwise (anything else is warned about at start by the configuration).  One thread
(``nfw-predict``) receives and answers every short command; the listings of ``GET_SAT_POS`` and
``PREDICT`` — up to a day of lines — are computed and sent by a second thread (``nfw-predict-list``),
one at a time, so a long listing never delays ``GET_SAT``.  At most :data:`LISTING_QUEUE` listings wait;
a request beyond that gets only the end-of-listing datagram (and one rate-limited warning).  A malformed
datagram gets ``Huh?`` and never stops the server.
"""

from __future__ import annotations

import logging
import queue
import socket
from collections.abc import Callable
from typing import Any

from nfwserver.core.service_thread import ServiceThread
from nfwserver.dialects.predict_protocol import END_OF_LISTING, PredictContext, PredictProtocol
from nfwserver.listen_errors import bind_failure
from nfwserver.listen_socket import datagram_socket

__all__ = ["DEFAULT_PORT", "PredictContext", "PredictUdpServer"]

log = logging.getLogger(__name__)
DEFAULT_PORT = 1210
LISTING_QUEUE = 8  #: listings waiting for the listing thread, at most
_STOP = object()


class _ListingThread(ServiceThread):
    """``nfw-predict-list``: sends the queued listings one at a time; stopped with a marker in the queue."""

    thread_name = "nfw-predict-list"

    def __init__(self, run: Callable[[], None], listings: queue.Queue[Any]) -> None:
        super().__init__()
        self._listings_run, self._listings = run, listings

    def _run(self) -> None:
        self._listings_run()

    def stop(self) -> None:
        if self.running:
            while True:  # make room for the stop marker: waiting listings are abandoned
                try:
                    self._listings.get_nowait()
                except queue.Empty:
                    break
            self._listings.put(_STOP)
        super().stop()


class PredictUdpServer(ServiceThread):
    """The UDP listener and its listing thread.  Construction does no I/O; :meth:`start` binds the socket
    (raising :class:`OSError` when the port is taken, with nothing left running) and starts the threads."""

    thread_name = "nfw-predict"

    def __init__(self, context: PredictContext, host: str = "127.0.0.1", port: int = DEFAULT_PORT) -> None:
        super().__init__()
        self.protocol = PredictProtocol(context)
        self.host, self.port = host, port
        self.sock: socket.socket | None = None
        self.address: tuple[str, int] = (host, port)
        self._listings: queue.Queue[Any] = queue.Queue(maxsize=LISTING_QUEUE)
        self._lister = _ListingThread(self._run_listings, self._listings)

    def start(self) -> None:
        if self.running:
            return
        try:
            sock = datagram_socket(self.host, self.port)
        except OSError as exc:
            raise bind_failure(exc, "dialects", self.host, self.port, host_key="predict_host",
                               port_key="predict_port", what="PREDICT UDP") from None
        sock.settimeout(0.2)
        self.sock = sock
        self.address = sock.getsockname()
        log.info("PREDICT protocol on UDP %s:%d", *self.address)
        super().start()
        self._lister.start()

    def _send(self, payload: bytes, peer: tuple[str, int]) -> None:
        sock = self.sock
        if sock is None:
            return
        try:
            sock.sendto(payload, peer)
        except OSError as exc:
            self.protocol.diagnostics.warning("send", "PREDICT reply to %s failed: %s", peer, exc)

    def _run(self) -> None:
        sock = self.sock
        assert sock is not None
        while not self._stop.is_set():
            try:
                data, peer = sock.recvfrom(2048)
            except TimeoutError:
                continue
            except OSError:
                if self._stop.is_set():
                    return
                continue
            if self.protocol.is_listing(data):
                try:
                    self._listings.put_nowait((data, peer))
                except queue.Full:
                    self.protocol.diagnostics.warning("listing-queue", "PREDICT listing from %s dropped: %d "
                                                      "listings already waiting", peer, LISTING_QUEUE)
                    self._send(END_OF_LISTING, peer)
                continue
            self._send(self.protocol.reply(data), peer)

    def _run_listings(self) -> None:
        while True:
            item = self._listings.get()
            if item is _STOP:
                return
            data, peer = item
            for datagram in self.protocol.listing(data):
                if self._stop.is_set():
                    return
                self._send(datagram, peer)

    def stop(self) -> None:
        super().stop()  # the receiving loop looks at the stop flag at least every 0.2 s (its socket timeout)
        self._lister.stop()
        if self.sock is not None:
            self.sock.close()
            self.sock = None
