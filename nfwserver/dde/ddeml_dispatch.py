"""From a DDEML callback to the transport-agnostic handler: the Windows transport's logic, OS-free.

DDEML rules this follows (Microsoft's DDEML documentation, in our words):

- ``XTYP_CONNECT`` carries the topic in ``hsz1`` and the service in ``hsz2``; returning TRUE accepts
  the conversation.  ``XTYP_CONNECT_CONFIRM`` then gives the new conversation handle.
- ``XTYP_REQUEST`` and ``XTYP_ADVREQ`` carry topic and item in ``hsz1``/``hsz2`` and the clipboard
  format in ``uFmt``; the server answers with a data handle it creates for that item and format
  (``DdeCreateDataHandle``), or NULL to refuse.  DDEML sends one ``XTYP_ADVREQ`` per advise loop
  after ``DdePostAdvise``; the handle then belongs to DDEML.
- ``XTYP_POKE`` and ``XTYP_EXECUTE`` deliver a data handle (read with ``DdeGetData``); the server
  answers ``DDE_FACK``, ``DDE_FBUSY`` or ``DDE_FNOTPROCESSED``.
- ``XTYP_ADVSTART`` returns TRUE to allow the advise loop; ``XTYP_ADVSTOP`` and
  ``XTYP_DISCONNECT`` are notifications (the return value is ignored).
- A callback must not raise: any exception is logged and the transaction refused.

The operating-system calls go through a small :class:`DdemlApi` object, so this module is tested on
any platform; :mod:`nfwserver.dde.windows_transport` supplies the user32 implementation.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Protocol

from nfwserver.dde import ddeml
from nfwserver.dde.transport import ConversationId, DdeServerHandler, PokeResult

log = logging.getLogger(__name__)


class DdemlApi(Protocol):
    """The three DDEML services the dispatcher needs."""

    def query_string(self, hsz: int) -> str: ...

    def get_data(self, hdata: int) -> bytes: ...

    def create_data(self, data: bytes, hsz_item: int, fmt: int) -> int: ...


class DdemlDispatcher:
    """The DDEML callback's body.  ``lookup(service)`` returns the handler registered for a service."""

    def __init__(self, lookup: Callable[[str], DdeServerHandler | None], api: DdemlApi) -> None:
        self.lookup = lookup
        self.api = api
        self._conversations: dict[int, tuple[ConversationId, DdeServerHandler]] = {}
        self._next_id = 1

    def conversation_count(self) -> int:
        return len(self._conversations)

    def __call__(self, utype: int, fmt: int, hconv: int, hsz1: int, hsz2: int, hdata: int,
                 data1: int = 0, data2: int = 0) -> int:
        try:
            return self._dispatch(utype, fmt, hconv or 0, hsz1 or 0, hsz2 or 0, hdata or 0)
        except Exception:  # a DDEML callback must never raise
            log.exception("DDE transaction 0x%04X failed", utype)
            return ddeml.DDE_FNOTPROCESSED if utype in (ddeml.XTYP_POKE, ddeml.XTYP_EXECUTE) else 0

    def _dispatch(self, utype: int, fmt: int, hconv: int, hsz1: int, hsz2: int, hdata: int) -> int:
        if utype == ddeml.XTYP_CONNECT:
            handler = self.lookup(self.api.query_string(hsz2))
            topic = self.api.query_string(hsz1)
            return int(bool(handler is not None and handler.on_connect(self.api.query_string(hsz2), topic)))
        if utype == ddeml.XTYP_CONNECT_CONFIRM:
            service = self.api.query_string(hsz2)
            handler = self.lookup(service)
            if handler is None:
                return 0
            conv = self._next_id
            self._next_id += 1
            self._conversations[hconv] = (conv, handler)
            handler.on_connect_confirm(conv, service, self.api.query_string(hsz1))
            return 0
        entry = self._conversations.get(hconv)
        if utype == ddeml.XTYP_DISCONNECT:
            if entry is not None:
                del self._conversations[hconv]
                entry[1].on_disconnect(entry[0])
            return 0
        if entry is None:  # a transaction on a conversation we never confirmed
            return ddeml.DDE_FNOTPROCESSED if utype in (ddeml.XTYP_POKE, ddeml.XTYP_EXECUTE) else 0
        conv, handler = entry
        topic = self.api.query_string(hsz1)
        if utype in (ddeml.XTYP_REQUEST, ddeml.XTYP_ADVREQ):
            item = self.api.query_string(hsz2)
            getter = handler.on_request if utype == ddeml.XTYP_REQUEST else handler.on_advise_request
            data = getter(conv, topic, item, fmt)
            return 0 if data is None else self.api.create_data(bytes(data), hsz2, fmt)
        if utype == ddeml.XTYP_POKE:
            result = handler.on_poke(conv, topic, self.api.query_string(hsz2), fmt, self.api.get_data(hdata))
            return int(result) if result in (PokeResult.FACK, PokeResult.FBUSY) else ddeml.DDE_FNOTPROCESSED
        if utype == ddeml.XTYP_EXECUTE:
            result = handler.on_execute(conv, topic, self.api.get_data(hdata))
            return int(result) if result in (PokeResult.FACK, PokeResult.FBUSY) else ddeml.DDE_FNOTPROCESSED
        if utype == ddeml.XTYP_ADVSTART:
            return int(bool(handler.on_advise_start(conv, topic, self.api.query_string(hsz2), fmt)))
        if utype == ddeml.XTYP_ADVSTOP:
            handler.on_advise_stop(conv, topic, self.api.query_string(hsz2), fmt)
            return 0
        return 0  # XTYP_WILDCONNECT (not offered), registrations, errors: nothing to do
