"""Under Wine: ``DdePostAdvise`` with the two workarounds Wine 8.0's DDEML needs (Windows' does not).

Chosen once by :func:`nfwserver.dde.advise_posting.choose_poster` when the transport starts under Wine;
on Windows nothing here runs.  What Wine 8.0 does differently (docs/PLATFORMS.md, docs/WINE.md):

1. Item atoms.  Wine's ``DdePostAdvise`` takes one reference on the item's global atom for all the
   ``WM_DDE_DATA`` it posts, while every client releases one: after the first client the atom is gone
   and the others drop their data.  :class:`WinePoster` adds the references Windows would (links - 1).
2. Data copies.  For every hot link Wine copies our data handle into a new moveable global block and
   posts it; to another process the message carries a copy of the bytes, and nobody frees the block,
   so after 65,536 posts every ``GlobalAlloc(GMEM_MOVEABLE)`` of the process fails.
   :class:`WineAdviseCopies` frees those blocks after each post (not while a conversation's client is
   in this process: there the block is the very one the client reads).
"""

from __future__ import annotations

import ctypes
import struct
from collections.abc import Callable

from nfwserver.dde import ddeml
from nfwserver.dde.ddeml_dispatch import DdemlApi

_GMEM_MOVEABLE = 0x0002


class WineAdviseCopies:  # pragma: no cover - Windows (Wine) only
    """Frees the copies of advise data that Wine 8.0's ``DdePostAdvise`` leaves behind.

    Each copy is a moveable global block (``WDML_DataHandle2Global``: a 4-byte ``WINE_DDEHEAD`` with no
    flags set, then the data).  kernelbase hands out free handles last-freed-first.  :meth:`reserve`
    takes ``count`` handles and frees them in reverse, so they are the next ones given out (our data
    handle for each link takes the first and gives it back, its copy takes the next); after the post,
    :meth:`release` frees those of them that now hold exactly a copy of data we returned for the post.
    """

    def __init__(self, kernel32: ddeml.Kernel32) -> None:
        self.k = kernel32
        self.freed = 0  #: copies freed so far

    def reserve(self, count: int) -> list[int]:
        handles: list[int] = []
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


class _RecordingApi:  # pragma: no cover - Windows (Wine) only
    """The dispatcher's DdemlApi, noting what Wine's copy of each data handle made during a post holds."""

    def __init__(self, api: DdemlApi) -> None:
        self.api = api
        self.made: set[bytes] | None = None  #: while a post runs: the expected copies (WINE_DDEHEAD + data)

    def query_string(self, hsz: int) -> str:
        return self.api.query_string(hsz)

    def get_data(self, hdata: int) -> bytes:
        return self.api.get_data(hdata)

    def create_data(self, data: bytes, hsz_item: int, fmt: int) -> int:
        if self.made is not None:  # WINE_DDEHEAD: no flags, the format; then the data
            self.made.add(struct.pack("<HH", 0, fmt) + data)
        return self.api.create_data(data, hsz_item, fmt)


class WinePoster:  # pragma: no cover - Windows (Wine) only
    """The :class:`~nfwserver.dde.advise_posting.AdvisePoster` for Wine's DDEML."""

    def __init__(self, user32: ddeml.User32, kernel32: ddeml.Kernel32) -> None:
        self.u, self.k = user32, kernel32
        self.copies = WineAdviseCopies(kernel32)
        self._api: _RecordingApi | None = None
        self._local: set[int] = set()  #: conversations whose client is in this process

    def wrap_api(self, api: DdemlApi) -> DdemlApi:
        self._api = _RecordingApi(api)
        return self._api

    def conversation_confirmed(self, hconv: int) -> None:
        if self._client_is_local(hconv):
            self._local.add(hconv)

    def conversation_ended(self, hconv: int) -> None:
        self._local.discard(hconv)

    def _client_is_local(self, hconv: int) -> bool:
        """Whether the conversation's client window belongs to this process (True if unknown)."""
        from ctypes import wintypes

        info = ddeml.conv_info(self.u, hconv)
        pid = wintypes.DWORD(0)
        if info is None or not info.hwndPartner:
            return True
        self.u.GetWindowThreadProcessId(info.hwndPartner, ctypes.byref(pid))
        return pid.value in (0, self.k.GetCurrentProcessId())

    def post(self, item: str, links: int, post_advise: Callable[[], bool]) -> bool:
        for _ in range(links - 1):  # the item-atom references Windows would take (module docstring, 1)
            self.k.GlobalAddAtomW(item)
        api = self._api
        if self._local or api is None:
            return post_advise()
        reserved = self.copies.reserve(links + 4)  # the copies (module docstring, 2)
        made: set[bytes] = set()
        api.made = made
        try:
            return post_advise()
        finally:
            api.made = None
            self.copies.release(reserved, made)

    def summary(self) -> str | None:
        return f"Wine: freed {self.copies.freed} advise data copies DdePostAdvise left behind"
