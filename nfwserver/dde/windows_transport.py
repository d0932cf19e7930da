"""The Windows DDE transport: DDEML through ctypes, on a thread of its own.

DDEML rules that shape this module (Microsoft's documentation, in our words):

- Every DDEML call for an instance must come from the thread that called ``DdeInitialize``, and
  DDEML delivers callbacks to that thread only while it retrieves and dispatches window messages.
  So the transport owns one thread: it initialises DDEML, registers names, runs the message loop,
  and performs every later call; other threads (the publisher calling :meth:`post_advise`, or
  shutdown) queue the request and wake the loop with ``PostThreadMessage``.
- Service names are registered with ``DdeNameService(DNS_REGISTER)`` using string handles created
  once with ``DdeCreateStringHandleW``; they are unregistered and freed, and the instance
  uninitialised, on :meth:`close`.
- ``DdePostAdvise(topic, item)`` makes DDEML send ``XTYP_ADVREQ`` to our callback for every advise
  loop on the item; data handles we return from the callback belong to DDEML.

Everything that is not a user32 call is in :mod:`nfwserver.dde.ddeml_dispatch` and is tested on
every platform.  On other operating systems constructing :class:`WindowsDdeTransport` raises
:class:`OSError`.
"""

from __future__ import annotations

import ctypes
import logging
import queue
import struct
import sys
import threading
import time
from collections.abc import Callable

from nfwserver.dde import ddeml
from nfwserver.dde.ddeml_dispatch import DdemlDispatcher
from nfwserver.dde.post_advise_stats import PostAdviseStats
from nfwserver.dde.transport import DdeServerHandler

log = logging.getLogger(__name__)

_WAKE = ddeml.WM_APP + 0x4E
_GMEM_MOVEABLE = 0x0002


class _User32Api:  # pragma: no cover - Windows only
    """The DdemlApi over user32 for one DDEML instance."""

    def __init__(self, user32, inst: int) -> None:
        self.u, self.inst = user32, inst
        #: when a set: what Wine's DdePostAdvise copies of each handle made look like (_WineAdviseCopies)
        self.wine_copies: set[bytes] | None = None

    def query_string(self, hsz: int) -> str:
        if not hsz:
            return ""
        n = self.u.DdeQueryStringW(self.inst, hsz, None, 0, ddeml.CP_WINUNICODE)
        buf = ctypes.create_unicode_buffer(n + 1)
        self.u.DdeQueryStringW(self.inst, hsz, buf, n + 1, ddeml.CP_WINUNICODE)
        return buf.value

    def get_data(self, hdata: int) -> bytes:
        if not hdata:
            return b""
        n = self.u.DdeGetData(hdata, None, 0, 0)
        buf = ctypes.create_string_buffer(n)
        self.u.DdeGetData(hdata, buf, n, 0)
        return buf.raw[:n]

    def create_data(self, data: bytes, hsz_item: int, fmt: int) -> int:
        buf = ctypes.create_string_buffer(data, len(data))
        if self.wine_copies is not None:  # WINE_DDEHEAD: no flags, the format; then the data
            self.wine_copies.add(struct.pack("<HH", 0, fmt) + data)
        return self.u.DdeCreateDataHandle(self.inst, buf, len(data), 0, hsz_item, fmt, 0) or 0


class _WineAdviseCopies:  # pragma: no cover - Windows (Wine) only
    """Frees the copies of advise data that Wine 8.0's ``DdePostAdvise`` leaves behind.

    For every hot link Wine's ``DdePostAdvise`` copies our data handle into a new moveable global
    block (``WDML_DataHandle2Global``: a 4-byte ``WINE_DDEHEAD`` with no flags set, then the data)
    and posts it.  To another process the message carries a copy of the block's bytes, and nobody
    frees the block; kernelbase has 65,536 moveable handles per process, so after that many posts
    every ``GlobalAlloc(GMEM_MOVEABLE)`` fails and the links get ``WM_DDE_DATA`` without data
    (100 links at 10 Hz: about 65 s; docs/PLATFORMS.md).  Windows' DDEML leaves no such block.

    kernelbase hands out free handles last-freed-first.  :meth:`reserve` takes ``count`` handles and
    frees them in reverse, so they are the next ones given out (our data handle for each link
    takes the first and gives it back, its copy takes the next); after the post, :meth:`release`
    frees those of them that now hold exactly a copy of data we returned for the post.  Copies
    posted to a conversation in this process are the very block the client reads: the transport
    does not call this while any conversation's client is in its own process.
    """

    def __init__(self, kernel32) -> None:
        from ctypes import wintypes

        self.k = kernel32
        self.k.GlobalAlloc.restype, self.k.GlobalAlloc.argtypes = ctypes.c_void_p, [wintypes.UINT, ctypes.c_size_t]
        self.k.GlobalFree.restype, self.k.GlobalFree.argtypes = ctypes.c_void_p, [ctypes.c_void_p]
        self.k.GlobalSize.restype, self.k.GlobalSize.argtypes = ctypes.c_size_t, [ctypes.c_void_p]
        self.k.GlobalLock.restype, self.k.GlobalLock.argtypes = ctypes.c_void_p, [ctypes.c_void_p]
        self.k.GlobalUnlock.restype, self.k.GlobalUnlock.argtypes = wintypes.BOOL, [ctypes.c_void_p]
        self.freed = 0  #: copies freed so far

    def reserve(self, count: int) -> list[int]:
        handles = []
        for _ in range(count):
            handle = self.k.GlobalAlloc(_GMEM_MOVEABLE, 1)
            if not handle:
                break
            handles.append(handle)
        for handle in reversed(handles):
            self.k.GlobalFree(handle)
        return handles

    def release(self, handles: list[int], copies: set[bytes]) -> None:
        sizes = {len(copy) for copy in copies}
        for handle in handles:
            size = self.k.GlobalSize(handle)  # 0 for a handle that is free again
            if size not in sizes:
                continue
            ptr = self.k.GlobalLock(handle)
            if not ptr:
                continue
            block = ctypes.string_at(ptr, size)
            self.k.GlobalUnlock(handle)
            if block in copies:
                self.k.GlobalFree(handle)
                self.freed += 1


class WindowsDdeTransport:  # pragma: no cover - Windows only
    """A :class:`~nfwserver.dde.transport.DdeServerTransport` over real DDEML."""

    def __init__(self, start_timeout_s: float = 10.0) -> None:
        if sys.platform != "win32":
            raise OSError("the Windows DDE transport needs Windows")
        self._handlers: dict[str, DdeServerHandler] = {}
        self._calls: queue.Queue[Callable[[], None]] = queue.Queue()
        self._ready = threading.Event()
        self._error: BaseException | None = None
        self._hsz: dict[str, int] = {}
        self._registered: dict[str, int] = {}
        self._closed = False
        self._failures = 0
        #: DdePostAdvise calls on the DDE thread (each runs one XTYP_ADVREQ per advise loop)
        self.post_advise_stats = PostAdviseStats()
        self._wine_atoms = False  #: set on the DDE thread when running under Wine (see post_advise)
        self._wine_copies: _WineAdviseCopies | None = None  #: under Wine: frees DdePostAdvise's leftovers
        self._local_convs: set[int] = set()  #: conversations whose client is in this process
        self._thread = threading.Thread(target=self._run, name="nfw-ddeml", daemon=True)
        self._thread.start()
        if not self._ready.wait(start_timeout_s) or self._error is not None:
            raise OSError(f"DDEML did not start: {self._error}")

    # -- the DDE thread ----------------------------------------------------------------------
    def _run(self) -> None:
        try:
            from ctypes import wintypes

            self.u = ddeml.load_user32()
            self._kernel32 = ctypes.WinDLL("kernel32")
            self._kernel32.GlobalAddAtomW.argtypes = [wintypes.LPCWSTR]
            self._kernel32.GlobalAddAtomW.restype = wintypes.ATOM
            self._wine_atoms = ddeml.running_under_wine()
            if self._wine_atoms:
                self._wine_copies = _WineAdviseCopies(self._kernel32)
            self.u.GetWindowThreadProcessId.restype = wintypes.DWORD
            self.u.GetWindowThreadProcessId.argtypes = [wintypes.HWND, ctypes.POINTER(wintypes.DWORD)]
            self._thread_id = ctypes.windll.kernel32.GetCurrentThreadId()
            inst = wintypes.DWORD(0)
            self._dispatcher: DdemlDispatcher | None = None
            self._callback = ddeml.CALLBACK_TYPE(self._on_callback)  # kept alive as long as the instance
            flags = ddeml.APPCLASS_STANDARD | ddeml.CBF_SKIP_REGISTRATIONS | ddeml.CBF_SKIP_UNREGISTRATIONS
            err = self.u.DdeInitializeW(ctypes.byref(inst), self._callback, flags, 0)
            if err != ddeml.DMLERR_NO_ERROR:
                raise OSError(f"DdeInitializeW failed with DMLERR 0x{err:04X}")
            self.inst = inst.value
            self._dispatcher = DdemlDispatcher(self._lookup, _User32Api(self.u, self.inst))
            msg = wintypes.MSG()
            # Make sure this thread has a message queue before anyone posts to it.
            self.u.PeekMessageW(ctypes.byref(msg), None, 0, 0, 0)
        except BaseException as exc:
            self._error = exc
            self._ready.set()
            return
        self._ready.set()
        while True:
            got = self.u.GetMessageW(ctypes.byref(msg), None, 0, 0)
            if got in (0, -1):
                break
            if msg.message == _WAKE and not msg.hWnd:
                self._drain()
                if self._closed:
                    break
                continue
            self.u.TranslateMessage(ctypes.byref(msg))
            self.u.DispatchMessageW(ctypes.byref(msg))
        self._shutdown()

    def _on_callback(self, utype, fmt, hconv, hsz1, hsz2, hdata, data1, data2):
        if self._dispatcher is None:
            return 0
        if utype == ddeml.XTYP_CONNECT_CONFIRM and self._client_is_local(hconv or 0):
            self._local_convs.add(hconv or 0)
        elif utype == ddeml.XTYP_DISCONNECT:
            self._local_convs.discard(hconv or 0)
        return self._dispatcher(utype, fmt, hconv or 0, hsz1 or 0, hsz2 or 0, hdata or 0, data1, data2) or None

    def _client_is_local(self, hconv: int) -> bool:
        """Whether the conversation's client window belongs to this process (True if unknown)."""
        from ctypes import wintypes

        info = ddeml.ConvInfo()
        info.cb = ctypes.sizeof(ddeml.ConvInfo)
        pid = wintypes.DWORD(0)
        if not self.u.DdeQueryConvInfo(hconv, ddeml.QID_SYNC, ctypes.byref(info)) or not info.hwndPartner:
            return True
        self.u.GetWindowThreadProcessId(info.hwndPartner, ctypes.byref(pid))
        return pid.value in (0, self._kernel32.GetCurrentProcessId())

    def _lookup(self, service: str) -> DdeServerHandler | None:
        return self._handlers.get(service.upper())

    def _string(self, text: str) -> int:
        key = text.upper()
        if key not in self._hsz:
            self._hsz[key] = self.u.DdeCreateStringHandleW(self.inst, text, ddeml.CP_WINUNICODE)
        return self._hsz[key]

    def _drain(self) -> None:
        while True:
            try:
                call = self._calls.get_nowait()
            except queue.Empty:
                return
            try:
                call()
            except Exception:  # only calls nobody waits for get here (see _call); rate-limited
                self._failures += 1
                if self._failures == 1 or self._failures % 600 == 0:
                    log.exception("DDE transport call failed (%d failures so far)", self._failures)

    def _shutdown(self) -> None:
        for service in list(self._registered):
            self.u.DdeNameService(self.inst, self._registered.pop(service), None, ddeml.DNS_UNREGISTER)
        for hsz in self._hsz.values():
            self.u.DdeFreeStringHandle(self.inst, hsz)
        self._hsz.clear()
        self.u.DdeUninitialize(self.inst)

    def _call(self, fn: Callable[[], None], wait: bool = True, timeout_s: float = 5.0) -> None:
        """Run ``fn`` on the DDE thread.  With ``wait``, its exception is raised here, in the caller;
        a DDE thread that does not answer within ``timeout_s`` raises :class:`TimeoutError`."""
        if threading.current_thread() is self._thread:
            fn()
            return
        if not wait:
            self._calls.put(fn)
            self.u.PostThreadMessageW(self._thread_id, _WAKE, 0, 0)
            return
        done = threading.Event()
        failure: list[BaseException] = []

        def wrapped() -> None:
            try:
                fn()
            except BaseException as exc:
                failure.append(exc)
            finally:
                done.set()

        self._calls.put(wrapped)
        if not self.u.PostThreadMessageW(self._thread_id, _WAKE, 0, 0):
            raise OSError("the DDE thread has stopped")
        if not done.wait(timeout_s):
            raise TimeoutError(f"the DDE thread did not answer within {timeout_s} s")
        if failure:
            raise failure[0]

    # -- DdeServerTransport ----------------------------------------------------------------
    def register_service(self, service: str, handler: DdeServerHandler) -> None:
        def do() -> None:
            self._handlers[service.upper()] = handler
            hsz = self._string(service)
            if not self.u.DdeNameService(self.inst, hsz, None, ddeml.DNS_REGISTER):
                self._handlers.pop(service.upper(), None)
                raise OSError(f"DdeNameService could not register {service} "
                              f"(DMLERR 0x{self.u.DdeGetLastError(self.inst):04X})")
            self._registered[service.upper()] = hsz
            log.info("DDE service %s registered", service)

        self._call(do)

    def unregister_service(self, service: str) -> None:
        def do() -> None:
            hsz = self._registered.pop(service.upper(), None)
            if hsz is not None:
                self.u.DdeNameService(self.inst, hsz, None, ddeml.DNS_UNREGISTER)
            self._handlers.pop(service.upper(), None)

        self._call(do)

    def post_advise(self, topic: str, item: str) -> None:
        def do() -> None:
            start = time.perf_counter()
            links = self._dispatcher.advise_links(item) if self._dispatcher is not None else -1
            if links == 0:
                # Nobody advises on the item: DDEML would post nothing.  Skipping the call also keeps
                # Wine's DdePostAdvise from taking an item-atom reference that nobody releases.
                self.post_advise_stats.add(time.perf_counter() - start, 0)
                return
            if self._wine_atoms:
                # Wine's DdePostAdvise takes one reference on the item's global atom for all the
                # WM_DDE_DATA it posts, while every client releases one: after the first client the
                # atom is gone and the others drop their data.  Add the references Windows would.
                for _ in range(links - 1):
                    self._kernel32.GlobalAddAtomW(item)
            api = self._dispatcher.api if self._dispatcher is not None else None
            copies = self._wine_copies if not self._local_convs and isinstance(api, _User32Api) else None
            if copies is None:
                ok = self.u.DdePostAdvise(self.inst, self._string(topic), self._string(item))
            else:  # under Wine: free the copies its DdePostAdvise leaves (_WineAdviseCopies)
                assert isinstance(api, _User32Api)
                reserved = copies.reserve(links + 4)
                api.wine_copies = made = set()
                try:
                    ok = self.u.DdePostAdvise(self.inst, self._string(topic), self._string(item))
                finally:
                    api.wine_copies = None
                    copies.release(reserved, made)
            self.post_advise_stats.add(time.perf_counter() - start, links)
            if not ok:
                err = self.u.DdeGetLastError(self.inst)
                raise OSError(f"DdePostAdvise {topic}/{item} failed with DMLERR 0x{err:04X}")

        self._call(do, wait=False)

    def close(self) -> None:
        if self._closed:
            return

        def do() -> None:
            self._closed = True

        self._call(do, wait=False)
        self._thread.join(5.0)
        log.info("%s", self.post_advise_stats.summary())  # the DDE thread has stopped adding
        if self._wine_copies is not None:
            log.info("Wine: freed %d advise data copies DdePostAdvise left behind", self._wine_copies.freed)
