"""The DDE transport a station serves on by default: real DDEML on Windows, the fake one elsewhere.

The choice is the station builder's: :mod:`nfwserver.dde` holds the transport interface and the Nova adapter,
:mod:`nfwserver.fake_dde` implements the interface, and neither imports the other's side of it.
"""

from __future__ import annotations

import logging
import sys

from nfwserver.dde.transport import DdeServerTransport
from nfwserver.fake_dde import FakeDdeSystem

log = logging.getLogger(__name__)

FAKE_NOTE = "no Windows DDE here: serving on the in-process fake DDE transport (console and local tools)"


def default_transport(platform: str = sys.platform) -> tuple[DdeServerTransport, str]:
    """The platform's DDE transport and a sentence describing it.

    On Windows (``platform == "win32"``) the DDEML transport; when it cannot start — it raises
    :class:`OSError` (DDEML refused, no window station) or :class:`ImportError` — the station
    still runs, on the in-process fake DDE transport, and the sentence says why.
    """
    if platform == "win32":
        try:
            from nfwserver.dde.windows_transport import WindowsDdeTransport

            return WindowsDdeTransport(), "serving real DDE (DDEML)"
        except (ImportError, OSError) as exc:
            log.error("the Windows DDE transport did not start: %s", exc)
            return (FakeDdeSystem().server_transport(),
                    f"real DDE failed to start ({exc}): serving on the in-process fake DDE transport only")
    return FakeDdeSystem().server_transport(), FAKE_NOTE
