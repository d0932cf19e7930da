"""Choosing the DDE transport for this platform."""

from __future__ import annotations

import logging
import sys

from nfwserver.dde.transport import DdeServerTransport

log = logging.getLogger(__name__)


def default_transport() -> tuple[DdeServerTransport, str]:
    """The platform's DDE transport and a sentence describing it.

    On Windows, real DDE through DDEML; if that cannot start (no DDEML, or it fails to initialise)
    the reason is logged and the in-process transport serves instead, as it does everywhere else.
    """
    from nfwserver.fake_dde import FakeDdeSystem

    if sys.platform == "win32":
        try:
            from nfwserver.dde.windows_transport import WindowsDdeTransport

            return WindowsDdeTransport(), "serving real DDE (DDEML)"
        except (ImportError, OSError, RuntimeError) as exc:
            log.error("real DDE could not start (%s): serving on the in-process transport only", exc)
    return (FakeDdeSystem().server_transport(),
            "no Windows DDE here: serving on the in-process DDE transport (console and local tools)")
