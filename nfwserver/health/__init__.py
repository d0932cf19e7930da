"""Link health: the one recovery mechanism every link of the station shares.

A *link* is anything that can fail and come back by itself: the rotor, the radio, an element
source, the state file, a listener.  Each has one :class:`~nfwserver.health.link_health.LinkHealth`:
set on a failure with its reason, retried after a bounded backoff, cleared on the first success.
The station keeps them on one :class:`~nfwserver.health.board.HealthBoard`, which ``STATUS``, the
console and the web page read.  Nothing latches.
"""

from nfwserver.health.board import HealthBoard
from nfwserver.health.link_health import Backoff, Fault, LinkHealth

__all__ = ["Backoff", "Fault", "HealthBoard", "LinkHealth"]
