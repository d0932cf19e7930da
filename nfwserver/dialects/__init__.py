"""Other trackers' interfaces served from the same session: Orbitron, WXtrack and SatPC32 DDE, PREDICT's UDP.

Each DDE dialect is a small :class:`~nfwserver.dialects.base.Dialect` record (names and a formatter);
:class:`~nfwserver.dialects.dde_service.DialectServer` serves any of them on a DDE transport next to
Nova's, updated from the Nova core's ticks.  :mod:`nfwserver.dialects.predict_udp` serves PREDICT's UDP
socket protocol (:mod:`~nfwserver.dialects.predict_protocol`; listings in
:mod:`~nfwserver.dialects.predict_listing`).
"""

from typing import TYPE_CHECKING  # noqa: E402

from nfwserver.lazy_exports import lazy_exports  # noqa: E402

_EXPORTS = {
    "DialectServer": "dde_service",
    "ORBITRON": "orbitron",
    "SATPC32": "satpc32",
    "WXTRACK": "wxtrack",
    "PredictUdpServer": "predict_udp",
    "PredictContext": "predict_udp",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)

if TYPE_CHECKING:  # the names as type checkers see them; at run time each module loads on first use
    from nfwserver.dialects.dde_service import DialectServer as DialectServer
    from nfwserver.dialects.orbitron import ORBITRON as ORBITRON
    from nfwserver.dialects.predict_udp import PredictContext as PredictContext
    from nfwserver.dialects.predict_udp import PredictUdpServer as PredictUdpServer
    from nfwserver.dialects.satpc32 import SATPC32 as SATPC32
    from nfwserver.dialects.wxtrack import WXTRACK as WXTRACK
