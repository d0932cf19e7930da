"""A small DDEML client through ctypes (Windows): talk to a station the way legacy clients do.

Usage (Windows)::

    client = DdemlClient()                       # ansi=True: a DdeInitializeA client, like VB6/Delphi
    conv = client.connect("NFW32", "NFW_DATA")
    client.poke(conv, "NFW_SERVER", "TUNE ON")   # raises DdeRefused unless the server answers DDE_FACK
    print(client.request_text(conv, "NFW_SERVER"))
    client.start_advise(conv, "NFW_SERVER")      # hot link; warm: hot=False
    client.pump(2.0)                             # advise data arrives while messages are pumped
    print(client.received)

All calls must come from the thread that created the client (a DDEML rule).  Allowances for
Wine's DDEML (docs/PLATFORMS.md): a refused poke may come back as a non-NULL handle with a result
word lacking ``DDE_FACK`` (Windows: NULL and ``DMLERR_NOTPROCESSED``), so pokes and executes check
the result word; and back-to-back synchronous transactions without dispatching messages get out of
step, so the client pumps messages for ``settle_s`` seconds before each transaction.
"""

from __future__ import annotations

import ctypes
import logging
import time
from collections import Counter
from collections.abc import Callable

from nfwserver.clock import SystemClock
from nfwserver.dde import ddeml
from nfwserver.dde.clipboard import ANSI_CODEPAGE, CF_TEXT, decode_text, encode_text
from nfwserver.ratelimited_log import RateLimitedLog

log = logging.getLogger(__name__)


class DdeRefused(OSError):
    """A transaction the server refused (or that failed); ``dmlerr`` is DdeGetLastError's code."""

    def __init__(self, message: str, dmlerr: int = 0) -> None:
        super().__init__(message)
        self.dmlerr = dmlerr


class DdemlClient:  # pragma: no cover - Windows only
    """One DDEML client instance; ``ansi`` selects DdeInitializeA and ANSI string handles."""

    def __init__(self, ansi: bool = False, settle_s: float = 0.02) -> None:
        from ctypes import wintypes

        self.u = ddeml.load_user32()  # OSError off Windows
        self._wintypes = wintypes
        self.ansi = ansi
        self.settle_s = settle_s
        self.callback_failures = 0  #: callbacks that raised (answered as unhandled, and logged)
        self._failures = RateLimitedLog(log, SystemClock(), 60.0)
        inst = wintypes.DWORD(0)
        self._callback = ddeml.CALLBACK_TYPE(self._on_callback)
        init = self.u.DdeInitializeA if ansi else self.u.DdeInitializeW
        err = init(ctypes.byref(inst), self._callback, ddeml.APPCMD_CLIENTONLY, 0)
        if err != ddeml.DMLERR_NO_ERROR:
            raise OSError(f"DdeInitialize failed with DMLERR 0x{err:04X}")
        self.inst = inst.value
        self._strings: dict[str, int] = {}
        #: (item, data or None for a warm-link notification), in arrival order
        self.received: list[tuple[str, bytes | None]] = []
        #: advise notifications per conversation handle
        self.advise_counts: Counter[int] = Counter()
        #: conversations the server ended (XTYP_DISCONNECT)
        self.disconnected: set[int] = set()
        self.keep_data = True

    # -- strings and data ------------------------------------------------------------------
    def _hsz(self, text: str) -> int:
        if text not in self._strings:
            if self.ansi:
                handle = self.u.DdeCreateStringHandleA(self.inst, text.encode(ANSI_CODEPAGE), ddeml.CP_WINANSI)
            else:
                handle = self.u.DdeCreateStringHandleW(self.inst, text, ddeml.CP_WINUNICODE)
            if not handle:
                raise self._error(f"DdeCreateStringHandle for {text!r}")
            self._strings[text] = handle
        return self._strings[text]

    def _query(self, hsz: int) -> str:
        if self.ansi:
            n = self.u.DdeQueryStringA(self.inst, hsz, None, 0, ddeml.CP_WINANSI)
            abuf = ctypes.create_string_buffer(n + 1)
            self.u.DdeQueryStringA(self.inst, hsz, abuf, n + 1, ddeml.CP_WINANSI)
            return abuf.value.decode(ANSI_CODEPAGE, errors="replace")
        n = self.u.DdeQueryStringW(self.inst, hsz, None, 0, ddeml.CP_WINUNICODE)
        buf = ctypes.create_unicode_buffer(n + 1)
        self.u.DdeQueryStringW(self.inst, hsz, buf, n + 1, ddeml.CP_WINUNICODE)
        return buf.value

    def _read(self, hdata: int) -> bytes:
        n = self.u.DdeGetData(hdata, None, 0, 0)
        buf = ctypes.create_string_buffer(n)
        self.u.DdeGetData(hdata, buf, n, 0)
        return buf.raw[:n]

    def _on_callback(self, utype: int, fmt: int, hconv: int | None, hsz1: int | None, hsz2: int | None,
                     hdata: int | None, data1: int, data2: int) -> int | None:
        try:
            if utype == ddeml.XTYP_ADVDATA:
                self.advise_counts[hconv or 0] += 1
                if self.keep_data:
                    self.received.append((self._query(hsz2 or 0), self._read(hdata) if hdata else None))
                return ddeml.DDE_FACK
            if utype == ddeml.XTYP_DISCONNECT:
                self.disconnected.add(hconv or 0)
        except Exception:  # a DDEML callback must not raise: counted, logged (a line a minute at most), unhandled
            self.callback_failures += 1
            self._failures.log(logging.ERROR, "callback", "DDEML client callback failed (type 0x%04X)", utype,
                               exc_info=True)
            return None
        return None

    def ended_by_server(self, conv: int) -> bool:
        """The server ended ``conv``: XTYP_DISCONNECT arrived, or (Wine, whose client DDEML never
        delivers XTYP_DISCONNECT) DdeQueryConvInfo reports the conversation terminated or gone."""
        if conv in self.disconnected:
            return True
        info = ddeml.conv_info(self.u, conv)
        if info is None:
            return True  # DDEML no longer knows the conversation
        return bool(info.wStatus & ddeml.ST_TERMINATED) or not info.wStatus & ddeml.ST_CONNECTED

    def _error(self, what: str) -> DdeRefused:
        err = self.u.DdeGetLastError(self.inst)
        return DdeRefused(f"{what} failed with DMLERR 0x{err:04X}", err)

    # -- transactions ----------------------------------------------------------------------
    def connect(self, service: str, topic: str) -> int:
        conv = self.u.DdeConnect(self.inst, self._hsz(service), self._hsz(topic), None)
        if not conv:
            raise self._error(f"DdeConnect to {service}/{topic}")
        return conv

    def _transact(self, conv: int, item: str, fmt: int, xtype: int, payload: bytes | None = None,
                  timeout_ms: int = 5000) -> tuple[int, int]:
        if self.settle_s:
            self.pump(self.settle_s)
        result = self._wintypes.DWORD(0)
        buf = ctypes.create_string_buffer(payload, len(payload)) if payload is not None else None
        hsz_item = self._hsz(item) if item else None
        handle = self.u.DdeClientTransaction(buf, len(payload) if payload is not None else 0, conv, hsz_item,
                                             fmt, xtype, timeout_ms, ctypes.byref(result))
        if not handle:
            raise self._error(f"transaction 0x{xtype:04X} on {item or 'the topic'}")
        return handle, result.value

    def _acknowledged(self, conv: int, item: str, fmt: int, xtype: int, payload: bytes) -> None:
        _, result = self._transact(conv, item, fmt, xtype, payload)
        if not result & ddeml.DDE_FACK:  # Wine: TRUE with result 0 when the server refused
            raise DdeRefused(f"transaction 0x{xtype:04X} on {item or 'the topic'} not acknowledged "
                             f"(result 0x{result:04X})", ddeml.DMLERR_NOTPROCESSED)

    def request(self, conv: int, item: str, fmt: int = CF_TEXT) -> bytes:
        handle, _ = self._transact(conv, item, fmt, ddeml.XTYP_REQUEST)
        try:
            return self._read(handle)
        finally:
            self.u.DdeFreeDataHandle(handle)

    def request_text(self, conv: int, item: str, fmt: int = CF_TEXT) -> str:
        return decode_text(self.request(conv, item, fmt), fmt)

    def poke(self, conv: int, item: str, text: str | bytes, fmt: int = CF_TEXT) -> None:
        """Poke ``text`` (encoded with its NUL) or raw ``bytes``; raises :class:`DdeRefused` if refused."""
        payload = text if isinstance(text, bytes) else encode_text(text, fmt)
        self._acknowledged(conv, item, fmt, ddeml.XTYP_POKE, payload)

    def execute(self, conv: int, command: str | bytes) -> None:
        """Execute ``command``: a string goes in the instance's character set, bytes as given."""
        if isinstance(command, bytes):
            payload = command
        else:
            payload = command.encode(ANSI_CODEPAGE) + b"\x00" if self.ansi else command.encode("utf-16-le") + b"\0\0"
        self._acknowledged(conv, "", 0, ddeml.XTYP_EXECUTE, payload)

    def start_advise(self, conv: int, item: str, fmt: int = CF_TEXT, hot: bool = True,
                     timeout_ms: int = 5000) -> None:
        self._transact(conv, item, fmt, ddeml.XTYP_ADVSTART | (0 if hot else ddeml.XTYPF_NODATA), None, timeout_ms)

    def stop_advise(self, conv: int, item: str, fmt: int = CF_TEXT) -> None:
        self._transact(conv, item, fmt, ddeml.XTYP_ADVSTOP)

    def pump(self, seconds: float, until: Callable[[], bool] | None = None) -> bool:
        """Dispatch window messages for ``seconds`` (advise data and disconnects arrive meanwhile),
        or until ``until()`` is true; returns whether it became true."""
        msg = self._wintypes.MSG()
        deadline = time.monotonic() + seconds
        while True:
            while self.u.PeekMessageW(ctypes.byref(msg), None, 0, 0, ddeml.PM_REMOVE):
                self.u.TranslateMessage(ctypes.byref(msg))
                self.u.DispatchMessageW(ctypes.byref(msg))
            if until is not None and until():
                return True
            remaining_ms = int((deadline - time.monotonic()) * 1000)
            if remaining_ms <= 0:
                return False
            self.u.MsgWaitForMultipleObjects(0, None, False, min(remaining_ms, 50), ddeml.QS_ALLINPUT)

    def disconnect(self, conv: int) -> None:
        self.u.DdeDisconnect(conv)

    def close(self) -> None:
        for handle in self._strings.values():
            self.u.DdeFreeStringHandle(self.inst, handle)
        self._strings.clear()
        self.u.DdeUninitialize(self.inst)
