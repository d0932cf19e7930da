"""Nova's TCP server: a greeting, ``SUMMARY``, the Nova commands, ``STATUS`` and ``WATCH`` on port 8090.

The names below are imported on first use (:mod:`nfwserver.lazy_exports`), so that the one-question client
(``nfwserver status``, ``poke``) does not load the server and the station core.
"""

from nfwserver.lazy_exports import lazy_exports

_EXPORTS = {"GREETING": "greeting", "NovaTcpProtocol": "protocol", "NovaTcpServer": "server"}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
