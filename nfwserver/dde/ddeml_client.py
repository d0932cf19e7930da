"""A small DDEML client through ctypes (Windows): check a station the way legacy clients talk to it.

Usage (Windows)::

    client = DdemlClient()
    conv = client.connect("NFW32", "NFW_DATA")
    client.poke(conv, "NFW_SERVER", "TUNE ON")
    print(client.request_text(conv, "NFW_SERVER"))
    client.start_advise(conv, "NFW_SERVER")      # hot link; warm: hot=False
    client.pump(2.0)                             # advise data arrives while messages are pumped
    print(client.received)

All calls must come from the thread that created the client (a DDEML rule).
"""

from __future__ import annotations

import ctypes
import sys
import time

from nfwserver.dde import ddeml
from nfwserver.dde.clipboard import CF_TEXT, decode_text, encode_text


class DdemlClient:  # pragma: no cover - Windows only
    def __init__(self) -> None:
        if sys.platform != "win32":
            raise OSError("DDEML exists only on Windows")
        from ctypes import wintypes

        self.u = ddeml.load_user32()
        self._wintypes = wintypes
        inst = wintypes.DWORD(0)
        self._callback = ddeml.CALLBACK_TYPE(self._on_callback)
        err = self.u.DdeInitializeW(ctypes.byref(inst), self._callback, ddeml.APPCMD_CLIENTONLY, 0)
        if err != ddeml.DMLERR_NO_ERROR:
            raise OSError(f"DdeInitializeW failed with DMLERR 0x{err:04X}")
        self.inst = inst.value
        self._strings: list[int] = []
        #: (item, data or None for a warm-link notification), in arrival order
        self.received: list[tuple[str, bytes | None]] = []

    def _hsz(self, text: str) -> int:
        handle = self.u.DdeCreateStringHandleW(self.inst, text, ddeml.CP_WINUNICODE)
        self._strings.append(handle)
        return handle

    def _query(self, hsz: int) -> str:
        n = self.u.DdeQueryStringW(self.inst, hsz, None, 0, ddeml.CP_WINUNICODE)
        buf = ctypes.create_unicode_buffer(n + 1)
        self.u.DdeQueryStringW(self.inst, hsz, buf, n + 1, ddeml.CP_WINUNICODE)
        return buf.value

    def _read(self, hdata: int) -> bytes:
        n = self.u.DdeGetData(hdata, None, 0, 0)
        buf = ctypes.create_string_buffer(n)
        self.u.DdeGetData(hdata, buf, n, 0)
        return buf.raw[:n]

    def _on_callback(self, utype, fmt, hconv, hsz1, hsz2, hdata, data1, data2):
        if utype == ddeml.XTYP_ADVDATA:
            self.received.append((self._query(hsz2), self._read(hdata) if hdata else None))
            return ddeml.DDE_FACK
        return None

    def _error(self, what: str) -> OSError:
        return OSError(f"{what} failed with DMLERR 0x{self.u.DdeGetLastError(self.inst):04X}")

    def connect(self, service: str, topic: str) -> int:
        conv = self.u.DdeConnect(self.inst, self._hsz(service), self._hsz(topic), None)
        if not conv:
            raise self._error(f"DdeConnect to {service}/{topic}")
        return conv

    def _transact(self, conv: int, item: str, fmt: int, xtype: int, payload: bytes | None = None,
                  timeout_ms: int = 5000) -> int:
        result = self._wintypes.DWORD(0)
        buf = ctypes.create_string_buffer(payload, len(payload)) if payload is not None else None
        handle = self.u.DdeClientTransaction(buf, len(payload) if payload is not None else 0, conv, self._hsz(item),
                                             fmt, xtype, timeout_ms, ctypes.byref(result))
        if not handle:
            raise self._error(f"transaction 0x{xtype:04X} on {item}")
        return handle

    def request(self, conv: int, item: str, fmt: int = CF_TEXT) -> bytes:
        handle = self._transact(conv, item, fmt, ddeml.XTYP_REQUEST)
        try:
            return self._read(handle)
        finally:
            self.u.DdeFreeDataHandle(handle)

    def request_text(self, conv: int, item: str, fmt: int = CF_TEXT) -> str:
        return decode_text(self.request(conv, item, fmt), fmt)

    def poke(self, conv: int, item: str, text: str, fmt: int = CF_TEXT) -> None:
        self._transact(conv, item, fmt, ddeml.XTYP_POKE, encode_text(text, fmt))

    def execute(self, conv: int, command: str) -> None:
        self._transact(conv, "", 0, ddeml.XTYP_EXECUTE, encode_text(command))

    def start_advise(self, conv: int, item: str, fmt: int = CF_TEXT, hot: bool = True) -> None:
        self._transact(conv, item, fmt, ddeml.XTYP_ADVSTART | (0 if hot else ddeml.XTYPF_NODATA))

    def stop_advise(self, conv: int, item: str, fmt: int = CF_TEXT) -> None:
        self._transact(conv, item, fmt, ddeml.XTYP_ADVSTOP)

    def pump(self, seconds: float) -> None:
        """Dispatch window messages for ``seconds`` so advise data can arrive."""
        msg = self._wintypes.MSG()
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            while self.u.PeekMessageW(ctypes.byref(msg), None, 0, 0, 1):
                self.u.TranslateMessage(ctypes.byref(msg))
                self.u.DispatchMessageW(ctypes.byref(msg))
            time.sleep(0.01)

    def disconnect(self, conv: int) -> None:
        self.u.DdeDisconnect(conv)

    def close(self) -> None:
        for handle in self._strings:
            self.u.DdeFreeStringHandle(self.inst, handle)
        self._strings.clear()
        self.u.DdeUninitialize(self.inst)
