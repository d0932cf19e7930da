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
- Execute strings are converted by DDEML to the server instance's character set: an instance made
  with ``DdeInitializeW`` (ours) receives UTF-16 even from ANSI clients (seen under Wine 8.0; the
  DDEML documentation describes the same conversion).  :func:`execute_command` turns them back into
  the ``CF_TEXT`` bytes the handler expects.
- ``XTYP_ADVSTART`` returns TRUE to allow the advise loop; ``XTYP_ADVSTOP`` and
  ``XTYP_DISCONNECT`` are notifications (the return value is ignored).
- A callback must not raise: any exception is logged and the transaction refused.

The operating-system calls go through a small :class:`DdemlApi` object, so this module is tested on
any platform; :mod:`nfwserver.dde.windows_transport` supplies the user32 implementation.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

from nfwserver.dde import ddeml
from nfwserver.dde.clipboard import CF_TEXT, CF_UNICODETEXT, decode_text, encode_text
from nfwserver.dde.transport import ConversationId, DdeServerHandler, PokeResult

log = logging.getLogger(__name__)


class DdemlApi(Protocol):
    """The three DDEML services the dispatcher needs."""

    def query_string(self, hsz: int) -> str: ...

    def get_data(self, hdata: int) -> bytes: ...

    def create_data(self, data: bytes, hsz_item: int, fmt: int) -> int: ...


def execute_command(data: bytes, unicode_instance: bool = True) -> bytes:
    """An execute transaction's data as ``CF_TEXT`` bytes (cp1252, NUL-terminated).

    For a Unicode instance the data is UTF-16-LE; data that cannot be UTF-16 (an odd length
    with a non-NUL second byte, as from a DDEML that passed an ANSI string through) is taken
    as ANSI.  A one-character ANSI command followed by its NUL reads the same either way.
    """
    looks_utf16 = len(data) >= 2 and data[1] == 0 and (len(data) % 2 == 0 or data.endswith(b"\x00\x00"))
    if unicode_instance and looks_utf16:
        return encode_text(decode_text(data, CF_UNICODETEXT), CF_TEXT)
    return data


@dataclass(frozen=True)
class _Conversation:
    """A conversation DDEML confirmed: our id for it, its handler, and the names the client used."""

    conv: ConversationId
    handler: DdeServerHandler
    service: str
    topic: str


class DdemlDispatcher:
    """The DDEML callback's body.  ``lookup(service)`` returns the handler registered for a service."""

    def __init__(self, lookup: Callable[[str], DdeServerHandler | None], api: DdemlApi,
                 unicode_instance: bool = True) -> None:
        self.lookup = lookup
        self.api = api
        self.unicode_instance = unicode_instance  #: the instance was made with DdeInitializeW
        self._conversations: dict[int, _Conversation] = {}  #: by DDEML conversation handle
        self._links: set[tuple[int, str, int]] = set()  #: advise links DDEML holds: (hconv, ITEM, format)
        self._next_id = 1

    def conversation_count(self) -> int:
        return len(self._conversations)

    def handles(self) -> list[int]:
        """The DDEML handles (HCONV) of the open conversations."""
        return list(self._conversations)

    def describe(self, hconv: int) -> str:
        """``conversation 3 (NFW32/NFW_DATA)`` for the log; ``conversation handle 0x..`` if unknown."""
        entry = self._conversations.get(hconv)
        if entry is None:
            return f"conversation handle 0x{hconv:X}"
        return f"conversation {entry.conv} ({entry.service}/{entry.topic})"

    def drop(self, hconv: int) -> None:
        """Forget a conversation whose client is gone without ending it, as if ``XTYP_DISCONNECT``
        had come: its advise links end and its handler hears ``on_disconnect``.  A later callback
        for the handle is refused (an ``XTYP_ADVREQ`` gets no data, so DDEML posts nothing to it)."""
        self._dispatch(ddeml.XTYP_DISCONNECT, 0, hconv, 0, 0, 0)

    def advise_links(self, item: str) -> int:
        """Advise links DDEML holds on ``item`` (any conversation, topic or format; names compare
        case-insensitively, as DDEML compares string handles)."""
        key = item.upper()
        return sum(1 for _, linked, _ in self._links if linked == key)

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
            topic = self.api.query_string(hsz1)
            self._conversations[hconv] = _Conversation(conv, handler, service, topic)
            handler.on_connect_confirm(conv, service, topic)
            return 0
        entry = self._conversations.get(hconv)
        if utype == ddeml.XTYP_DISCONNECT:
            self._links = {link for link in self._links if link[0] != hconv}
            if entry is not None:
                del self._conversations[hconv]
                entry.handler.on_disconnect(entry.conv)
            return 0
        if entry is None:  # a transaction on a conversation we never confirmed
            return ddeml.DDE_FNOTPROCESSED if utype in (ddeml.XTYP_POKE, ddeml.XTYP_EXECUTE) else 0
        conv, handler = entry.conv, entry.handler
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
            command = execute_command(self.api.get_data(hdata), self.unicode_instance)
            result = handler.on_execute(conv, topic, command)
            return int(result) if result in (PokeResult.FACK, PokeResult.FBUSY) else ddeml.DDE_FNOTPROCESSED
        if utype == ddeml.XTYP_ADVSTART:
            item = self.api.query_string(hsz2)
            accepted = bool(handler.on_advise_start(conv, topic, item, fmt))
            if accepted:  # a second start on the same link changes it, DDEML keeps one link
                self._links.add((hconv, item.upper(), fmt))
            return int(accepted)
        if utype == ddeml.XTYP_ADVSTOP:
            item = self.api.query_string(hsz2)
            self._links.discard((hconv, item.upper(), fmt))
            handler.on_advise_stop(conv, topic, item, fmt)
            return 0
        return 0  # XTYP_WILDCONNECT (not offered), registrations, errors: nothing to do
