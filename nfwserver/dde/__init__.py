"""Nova for Windows' DDE interface: the Nova adapter, the transport interface, the Windows DDEML transport.
"""

from typing import TYPE_CHECKING

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

if TYPE_CHECKING:  # the names as type checkers see them; at run time each module loads on first use
    from nfwserver.dde.clipboard import CF_TEXT as CF_TEXT
    from nfwserver.dde.clipboard import CF_UNICODETEXT as CF_UNICODETEXT
    from nfwserver.dde.nova_service import NovaDdeService as NovaDdeService
    from nfwserver.dde.transport import (
        DdeServerHandler as DdeServerHandler,
    )
    from nfwserver.dde.transport import (
        DdeServerTransport as DdeServerTransport,
    )
    from nfwserver.dde.transport import (
        PokeResult as PokeResult,
    )
