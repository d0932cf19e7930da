"""Nova's TCP server: a greeting, ``SUMMARY``, the Nova commands, ``STATUS`` and ``WATCH`` on port 8090.

The names below are imported on first use (:mod:`nfwserver.lazy_exports`), so that the one-question client
(``nfwserver status``, ``poke``) does not load the server and the station core.
"""

from typing import TYPE_CHECKING

from nfwserver.lazy_exports import lazy_exports

_EXPORTS = {"GREETING": "greeting", "NovaTcpProtocol": "protocol", "NovaTcpServer": "server"}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)

if TYPE_CHECKING:  # the names as type checkers see them; at run time each module loads on first use
    from nfwserver.tcp.greeting import GREETING as GREETING
    from nfwserver.tcp.protocol import NovaTcpProtocol as NovaTcpProtocol
    from nfwserver.tcp.server import NovaTcpServer as NovaTcpServer
