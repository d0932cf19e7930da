"""Nova for Windows' DDE interface: the Nova adapter, the transport interface, the Windows DDEML transport.
"""

from nfwserver.lazy_exports import lazy_exports

_EXPORTS = {
    "NovaDdeService": "nova_service",
    "DdeServerHandler": "transport",
    "DdeServerTransport": "transport",
    "PokeResult": "transport",
    "CF_TEXT": "clipboard",
    "CF_UNICODETEXT": "clipboard",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
