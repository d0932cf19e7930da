"""Peers the TCP server refuses or closes, on record once a minute per peer *address*.

A refused connection (outside ``[tcp] allow``, over a cap with nobody to displace) and a connection closed for
speaking HTTP (:mod:`nfwserver.tcp.http_guard`) are counted always (:class:`~nfwserver.tcp.connection.TcpStats`,
shown in ``STATUS``), but written to the log and to the event stream at most once a minute per peer address,
with the number of the others since: the key is the address alone, never anything the peer sends or its port,
so a flood from one address -- whatever it varies -- costs one log line and one event a minute and never pushes
the operator's history off the page.
"""

from __future__ import annotations

import logging

from nfwserver.core.events import Direction
from nfwserver.core.station_core import StationCore
from nfwserver.ratelimited_log import RateLimitedLog

__all__ = ["PeerRefusals", "RECORD_INTERVAL_S"]

RECORD_INTERVAL_S = 60.0  #: clock seconds between two records for one address


class PeerRefusals:
    """Log lines (to ``logger``) and events (``core.events``) for refused peers, one per address a minute."""

    def __init__(self, core: StationCore, logger: logging.Logger) -> None:
        self.core = core
        self._log = RateLimitedLog(logger, core.clock, RECORD_INTERVAL_S)

    def record(self, address: str, peer: str, what: str) -> bool:
        """``peer`` (from ``address``, a peer key) was refused or closed because of ``what`` (our words, never
        the peer's); True when this one went on record."""
        earlier = self._log.suppressed(address)
        if not self._log.warning(address, "TCP connection from %s %s", peer, what):
            return False
        more = f" ({earlier} more from {address} since the last record)" if earlier else ""
        self.core.events.add(self.core.clock.now(), Direction.INFO, "note", f"connection {what}{more}",
                             client=peer, accepted=False)
        return True
