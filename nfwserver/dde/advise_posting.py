"""The transport's platform seam for ``DdePostAdvise``: how the DDE thread posts advise data.

:class:`~nfwserver.dde.windows_transport.WindowsDdeTransport` chooses a poster once, when its DDE
thread starts (:func:`choose_poster`): on Windows the :class:`DirectPoster`, which calls
``DdePostAdvise`` and nothing else; under Wine (ntdll exports ``wine_get_version``) the
:class:`~nfwserver.dde.wine_posting.WinePoster`, which works around two defects of Wine 8.0's
``DdePostAdvise`` (docs/WINE.md, docs/PLATFORMS.md).  The transport calls the poster on its DDE
thread only.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

from nfwserver.dde import ddeml
from nfwserver.dde.ddeml_dispatch import DdemlApi


class AdvisePoster(Protocol):
    """What the transport asks of its poster (DDE thread only)."""

    def wrap_api(self, api: DdemlApi) -> DdemlApi:
        """The DdemlApi the dispatcher gets (the poster may watch the data handles it makes)."""
        ...

    def conversation_confirmed(self, hconv: int) -> None:
        """DDEML confirmed the conversation ``hconv`` (XTYP_CONNECT_CONFIRM)."""
        ...

    def conversation_ended(self, hconv: int) -> None:
        """The conversation ``hconv`` ended (XTYP_DISCONNECT, or dropped because its client vanished)."""
        ...

    def post(self, item: str, links: int, post_advise: Callable[[], bool]) -> bool:
        """Run ``post_advise()`` (one ``DdePostAdvise`` on ``item``, which has ``links`` advise links,
        at least one) and return its result."""
        ...

    def summary(self) -> str | None:
        """A line for the log at stop, or None."""
        ...


class DirectPoster:
    """Windows: ``DdePostAdvise`` as documented, nothing around it."""

    def wrap_api(self, api: DdemlApi) -> DdemlApi:
        return api

    def conversation_confirmed(self, hconv: int) -> None:
        pass

    def conversation_ended(self, hconv: int) -> None:
        pass

    def post(self, item: str, links: int, post_advise: Callable[[], bool]) -> bool:
        return post_advise()

    def summary(self) -> str | None:
        return None


def choose_poster(user32: ddeml.User32, kernel32: ddeml.Kernel32) -> AdvisePoster:  # pragma: no cover - Windows
    """The poster for the DDEML this process runs on: Wine's workarounds only under Wine."""
    if ddeml.running_under_wine():
        from nfwserver.dde.wine_posting import WinePoster

        return WinePoster(user32, kernel32)
    return DirectPoster()
