"""The contract between the server core and a DDE transport.

A transport (the in-process :mod:`nfwserver.fake_dde`, or the Windows DDEML transport) owns the
conversations and the advise loops; the core owns the data.  The shape follows DDEML's server
callback: the transport turns each transaction a client starts into one call on the
:class:`DdeServerHandler` the service was registered with, and the core tells the transport when
an item's data changed with :meth:`DdeServerTransport.post_advise` (DDEML's ``DdePostAdvise``),
after which the transport asks the handler for the data once per advise loop on that item
(``XTYP_ADVREQ``) and delivers it (hot link) or only notifies the client (warm link).

Names (service, topic, item) reach the handler as the client spelled them; DDEML compares them
case-insensitively, so handlers must too.  Data is bytes in a clipboard format
(:mod:`nfwserver.dde.clipboard`).
"""

from __future__ import annotations

import enum
from typing import Protocol

#: Conversation handle: an opaque integer unique within one transport while the conversation lives.
ConversationId = int


class PokeResult(enum.IntEnum):
    """A server's answer to a poke or execute, as DDEML's DDE_F* acknowledgement flags."""

    FACK = 0x8000  #: accepted and processed
    FBUSY = 0x4000  #: busy, try again
    FNOTPROCESSED = 0x0000  #: refused


class DdeServerHandler(Protocol):
    """What a transport calls on the server side; one method per DDEML transaction type.

    Every method is called on the transport's thread.  A method that raises is treated by the
    transport as a refusal of that one transaction (logged), never as a failure of the transport.
    """

    def on_connect(self, service: str, topic: str) -> bool:
        """XTYP_CONNECT: may a client open a conversation on (service, topic)?"""
        ...

    def on_connect_confirm(self, conv: ConversationId, service: str, topic: str) -> None:
        """XTYP_CONNECT_CONFIRM: the conversation ``conv`` now exists."""
        ...

    def on_request(self, conv: ConversationId, topic: str, item: str, fmt: int) -> bytes | None:
        """XTYP_REQUEST: the item's data in ``fmt``, or None to refuse (unknown item or format)."""
        ...

    def on_poke(self, conv: ConversationId, topic: str, item: str, fmt: int, data: bytes) -> PokeResult:
        """XTYP_POKE: the client sends ``data`` to ``item``."""
        ...

    def on_execute(self, conv: ConversationId, topic: str, command: bytes) -> PokeResult:
        """XTYP_EXECUTE: the client sends a command string (raw bytes as received)."""
        ...

    def on_advise_start(self, conv: ConversationId, topic: str, item: str, fmt: int) -> bool:
        """XTYP_ADVSTART: may the client start an advise loop on (item, fmt)?"""
        ...

    def on_advise_request(self, conv: ConversationId, topic: str, item: str, fmt: int) -> bytes | None:
        """XTYP_ADVREQ: the current data for one advise loop after :meth:`DdeServerTransport.post_advise`."""
        ...

    def on_advise_stop(self, conv: ConversationId, topic: str, item: str, fmt: int) -> None:
        """XTYP_ADVSTOP: the client ended its advise loop on (item, fmt)."""
        ...

    def on_disconnect(self, conv: ConversationId) -> None:
        """XTYP_DISCONNECT: the conversation ended (client disconnect, or transport shutdown)."""
        ...


class DdeServerTransport(Protocol):
    """What the core calls on a transport."""

    def register_service(self, service: str, handler: DdeServerHandler) -> None:
        """Offer ``service`` (DDEML ``DdeNameService(DNS_REGISTER)``); its transactions go to ``handler``."""
        ...

    def unregister_service(self, service: str) -> None:
        """Withdraw ``service``; its open conversations are disconnected."""
        ...

    def post_advise(self, topic: str, item: str) -> None:
        """DdePostAdvise: the data of (topic, item) changed; serve every advise loop on it."""
        ...

    def close(self) -> None:
        """Unregister every service, disconnect every conversation and release resources."""
        ...
