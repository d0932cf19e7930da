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

How ``DdePostAdvise`` is called is the one platform seam: an
:class:`~nfwserver.dde.advise_posting.AdvisePoster` chosen once when the DDE thread starts (plain on
Windows; Wine 8.0's workarounds only under Wine, :mod:`nfwserver.dde.wine_posting`).

A client program that exits without ending its conversations (killed, crashed) leaves DDEML a
conversation whose window is gone: ``DdePostAdvise`` then fails (``DMLERR_POSTMSG_FAILED``; Wine
also stops at that link, so links after it get nothing).  The transport drops such conversations
with one log line each, as if the client had disconnected (:meth:`WindowsDdeTransport._drop_vanished`).

Everything that is not a user32 call is in :mod:`nfwserver.dde.ddeml_dispatch` and is tested on
every platform.  On other operating systems constructing :class:`WindowsDdeTransport` raises
:class:`OSError`.
"""

from __future__ import annotations

import ctypes
import logging
import queue
import sys
import threading
import time
from collections.abc import Callable

from nfwserver.dde import ddeml
from nfwserver.dde.advise_posting import AdvisePoster, choose_poster
from nfwserver.dde.ddeml_dispatch import DdemlDispatcher
from nfwserver.dde.post_advise_stats import PostAdviseStats
from nfwserver.dde.transport import DdeServerHandler

log = logging.getLogger(__name__)

_WAKE = ddeml.WM_APP + 0x4E


class _User32Api:  # pragma: no cover - Windows only
    """The DdemlApi over user32 for one DDEML instance."""

    def __init__(self, user32: ddeml.User32, inst: int) -> None:
        self.u, self.inst = user32, inst

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
        return self.u.DdeCreateDataHandle(self.inst, buf, len(data), 0, hsz_item, fmt, 0) or 0


class WindowsDdeTransport:  # pragma: no cover - Windows only
    """A :class:`~nfwserver.dde.transport.DdeServerTransport` over real DDEML."""

    def __init__(self, start_timeout_s: float = 10.0) -> None:
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
        self._dispatcher: DdemlDispatcher | None = None
        self._poster: AdvisePoster | None = None  #: chosen on the DDE thread at start (module docstring)
        self._thread = threading.Thread(target=self._run, name="nfw-ddeml", daemon=True)
        if sys.platform != "win32":
            raise OSError("the Windows DDE transport needs Windows")
        self._thread.start()
        if not self._ready.wait(start_timeout_s) or self._error is not None:
            raise OSError(f"DDEML did not start: {self._error}")

    # -- the DDE thread ----------------------------------------------------------------------
    def _run(self) -> None:
        try:
            from ctypes import wintypes

            self.u = ddeml.load_user32()
            self._kernel32 = ddeml.load_kernel32()
            self._poster = choose_poster(self.u, self._kernel32)
            self._thread_id = self._kernel32.GetCurrentThreadId()
            inst = wintypes.DWORD(0)
            self._callback = ddeml.CALLBACK_TYPE(self._on_callback)  # kept alive as long as the instance
            flags = ddeml.APPCLASS_STANDARD | ddeml.CBF_SKIP_REGISTRATIONS | ddeml.CBF_SKIP_UNREGISTRATIONS
            err = self.u.DdeInitializeW(ctypes.byref(inst), self._callback, flags, 0)
            if err != ddeml.DMLERR_NO_ERROR:
                raise OSError(f"DdeInitializeW failed with DMLERR 0x{err:04X}")
            self.inst = inst.value
            self._dispatcher = DdemlDispatcher(self._lookup, self._poster.wrap_api(_User32Api(self.u, self.inst)))
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

    def _on_callback(self, utype: int, fmt: int, hconv: int | None, hsz1: int | None, hsz2: int | None,
                     hdata: int | None, data1: int, data2: int) -> int | None:
        if self._dispatcher is None or self._poster is None:
            return 0
        if utype == ddeml.XTYP_CONNECT_CONFIRM:
            self._poster.conversation_confirmed(hconv or 0)
        elif utype == ddeml.XTYP_DISCONNECT:
            self._poster.conversation_ended(hconv or 0)
        return self._dispatcher(utype, fmt, hconv or 0, hsz1 or 0, hsz2 or 0, hdata or 0, data1, data2) or None

    def _lookup(self, service: str) -> DdeServerHandler | None:
        return self._handlers.get(service.upper())

    def _string(self, text: str) -> int:
        key = text.upper()
        if key not in self._hsz:
            hsz = self.u.DdeCreateStringHandleW(self.inst, text, ddeml.CP_WINUNICODE)
            if not hsz:
                raise OSError(f"DdeCreateStringHandleW could not make a handle for {text!r} "
                              f"(DMLERR 0x{self.u.DdeGetLastError(self.inst):04X})")
            self._hsz[key] = hsz
        return self._hsz[key]

    def _drain(self) -> None:
        while True:
            try:
                call = self._calls.get_nowait()
            except queue.Empty:
                return
            try:
                call()
            except Exception as exc:  # only calls nobody waits for get here (see _call); rate-limited
                self._failures += 1
                if self._failures == 1 or self._failures % 600 == 0:
                    if isinstance(exc, OSError):  # a DDEML call that failed: its message says which
                        log.warning("%s (%d DDE transport failures so far)", exc, self._failures)
                    else:
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
            try:
                hsz = self._string(service)  # DDEML makes no string handle for an empty name
            except OSError as exc:
                raise OSError(f"could not register {service!r}: {exc}") from None
            self._handlers[service.upper()] = handler
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
            dispatcher, poster = self._dispatcher, self._poster
            if dispatcher is None or poster is None:  # DDEML never started
                return
            start = time.perf_counter()
            links = dispatcher.advise_links(item)
            if links == 0:
                # Nobody advises on the item: DDEML would post nothing.  Skipping the call also keeps
                # Wine's DdePostAdvise from taking an item-atom reference that nobody releases.
                self.post_advise_stats.add(time.perf_counter() - start, 0)
                return
            hsz_topic, hsz_item = self._string(topic), self._string(item)
            ok = poster.post(item, links, lambda: bool(self.u.DdePostAdvise(self.inst, hsz_topic, hsz_item)))
            self.post_advise_stats.add(time.perf_counter() - start, links)
            if not ok:
                err = self.u.DdeGetLastError(self.inst)
                if not self._drop_vanished(err):
                    raise OSError(f"DdePostAdvise {topic}/{item} failed with DMLERR 0x{err:04X}")

        self._call(do, wait=False)

    def _drop_vanished(self, err: int) -> int:
        """After a failed ``DdePostAdvise``: drop every conversation whose client window is gone (the
        program exited without disconnecting), one log line each; return how many were dropped.

        DDEML keeps such a conversation and its advise links: every later post fails on it, and
        Wine's stops at it, so the links after it get nothing.  Dropped, the conversation is ended
        for the station as by ``XTYP_DISCONNECT``; ``DdeDisconnect`` lets DDEML free it (Wine 8.0
        ignores that call on a server's conversation, but then asks us for the link's data, gets
        none and posts nothing)."""
        dispatcher, poster = self._dispatcher, self._poster
        if dispatcher is None or poster is None:
            return 0
        dropped = 0
        for hconv in dispatcher.handles():
            if not self._client_vanished(hconv):
                continue
            name = dispatcher.describe(hconv)
            self.u.DdeDisconnect(hconv)
            poster.conversation_ended(hconv)
            dispatcher.drop(hconv)
            dropped += 1
            log.warning("DDE client of %s is gone without disconnecting (DdePostAdvise: DMLERR 0x%04X): "
                        "conversation dropped", name, err)
        return dropped

    def _client_vanished(self, hconv: int) -> bool:
        """DDEML no longer knows ``hconv``, or no longer counts it connected, or its client's window
        is gone."""
        info = ddeml.conv_info(self.u, hconv)
        if info is None:
            return True
        if not info.wStatus & ddeml.ST_CONNECTED:
            return True
        return bool(info.hwndPartner) and not self.u.IsWindow(info.hwndPartner)

    def close(self) -> None:
        if self._closed:
            return

        def do() -> None:
            self._closed = True

        self._call(do, wait=False)
        self._thread.join(5.0)
        log.info("%s", self.post_advise_stats.summary())  # the DDE thread has stopped adding
        summary = self._poster.summary() if self._poster is not None else None
        if summary is not None:
            log.info("%s", summary)
