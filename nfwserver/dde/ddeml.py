"""The parts of Windows' DDE Management Library (user32) nfwserver uses, declared with ctypes.

Importable on any OS: the constants are plain numbers, and :func:`load_user32` binds the
functions only when called on Windows.  Values are those of ``ddeml.h``.
"""

from __future__ import annotations

import ctypes
import sys
from collections.abc import Callable
from typing import Protocol, cast

# Transaction classes and flags.
XCLASS_BOOL = 0x1000
XCLASS_DATA = 0x2000
XCLASS_FLAGS = 0x4000
XCLASS_NOTIFICATION = 0x8000
XTYPF_NOBLOCK = 0x0002
XTYPF_NODATA = 0x0004
XTYPF_ACKREQ = 0x0008

# Transaction types.
XTYP_ERROR = 0x0000 | XCLASS_NOTIFICATION | XTYPF_NOBLOCK
XTYP_ADVDATA = 0x0010 | XCLASS_FLAGS
XTYP_ADVREQ = 0x0020 | XCLASS_DATA | XTYPF_NOBLOCK
XTYP_ADVSTART = 0x0030 | XCLASS_BOOL
XTYP_ADVSTOP = 0x0040 | XCLASS_NOTIFICATION
XTYP_EXECUTE = 0x0050 | XCLASS_FLAGS
XTYP_CONNECT = 0x0060 | XCLASS_BOOL | XTYPF_NOBLOCK
XTYP_CONNECT_CONFIRM = 0x0070 | XCLASS_NOTIFICATION | XTYPF_NOBLOCK
XTYP_XACT_COMPLETE = 0x0080 | XCLASS_NOTIFICATION
XTYP_POKE = 0x0090 | XCLASS_FLAGS
XTYP_REGISTER = 0x00A0 | XCLASS_NOTIFICATION | XTYPF_NOBLOCK
XTYP_REQUEST = 0x00B0 | XCLASS_DATA
XTYP_DISCONNECT = 0x00C0 | XCLASS_NOTIFICATION | XTYPF_NOBLOCK
XTYP_UNREGISTER = 0x00D0 | XCLASS_NOTIFICATION | XTYPF_NOBLOCK
XTYP_WILDCONNECT = 0x00E0 | XCLASS_DATA | XTYPF_NOBLOCK
XTYP_MASK = 0x00F0

# DdeInitialize flags.
APPCLASS_STANDARD = 0x00000000
APPCMD_CLIENTONLY = 0x00000010
CBF_FAIL_SELFCONNECTIONS = 0x00001000
CBF_SKIP_REGISTRATIONS = 0x00080000
CBF_SKIP_UNREGISTRATIONS = 0x00100000

# DdeNameService.
DNS_REGISTER = 0x0001
DNS_UNREGISTER = 0x0002

# Acknowledgement flags for pokes and executes.
DDE_FACK = 0x8000
DDE_FBUSY = 0x4000
DDE_FNOTPROCESSED = 0x0000

# Conversation status bits (CONVINFO.wStatus).
ST_CONNECTED = 0x0001
ST_TERMINATED = 0x0020
QID_SYNC = 0xFFFFFFFF

CP_WINANSI = 1004
CP_WINUNICODE = 1200
DMLERR_NO_ERROR = 0
DMLERR_NOTPROCESSED = 0x4009
DMLERR_POSTMSG_FAILED = 0x400C
PM_REMOVE = 0x0001
QS_ALLINPUT = 0x04FF
TIMEOUT_ASYNC = 0xFFFFFFFF
WM_APP = 0x8000

#: DDEML callback: HDDEDATA CALLBACK(UINT uType, UINT uFmt, HCONV, HSZ, HSZ, HDDEDATA, ULONG_PTR, ULONG_PTR)
if sys.platform == "win32":  # pragma: no cover - Windows only
    CALLBACK_TYPE = ctypes.WINFUNCTYPE(ctypes.c_void_p, ctypes.c_uint, ctypes.c_uint, ctypes.c_void_p,
                                       ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t,
                                       ctypes.c_size_t)
else:
    CALLBACK_TYPE = ctypes.CFUNCTYPE(ctypes.c_void_p, ctypes.c_uint, ctypes.c_uint, ctypes.c_void_p,
                                     ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t,
                                     ctypes.c_size_t)


def running_under_wine() -> bool:  # pragma: no cover - Windows only
    """True when this "Windows" is Wine (its ntdll exports ``wine_get_version``)."""
    if sys.platform != "win32":
        return False
    try:
        return hasattr(ctypes.WinDLL("ntdll"), "wine_get_version")
    except OSError:
        return False


class ConvInfo(ctypes.Structure):  # pragma: no cover - layout of ddeml.h's CONVINFO (64-bit)
    _fields_ = [("cb", ctypes.c_uint32), ("hUser", ctypes.c_size_t), ("hConvPartner", ctypes.c_void_p),
                ("hszSvcPartner", ctypes.c_void_p), ("hszServiceReq", ctypes.c_void_p),
                ("hszTopic", ctypes.c_void_p), ("hszItem", ctypes.c_void_p), ("wFmt", ctypes.c_uint),
                ("wType", ctypes.c_uint), ("wStatus", ctypes.c_uint), ("wConvst", ctypes.c_uint),
                ("wLastError", ctypes.c_uint), ("hConvList", ctypes.c_void_p),
                # CONVCONTEXT: cb, wFlags, wCountryID, iCodePage, dwLangID, dwSecurity, SECURITY_QOS (12 bytes)
                ("ConvCtxt", ctypes.c_uint32 * 9), ("hwnd", ctypes.c_void_p), ("hwndPartner", ctypes.c_void_p)]


#: A ctypes function whose result is a number (UINT, DWORD, BOOL, ATOM, LRESULT).
Numeric = Callable[..., int]
#: A ctypes function whose result is a handle (``c_void_p``): an int, or None for NULL.
Handle = Callable[..., "int | None"]


class User32(Protocol):
    """The user32 functions :func:`load_user32` declares, as mypy sees them (arguments unchecked;
    ctypes checks them against ``argtypes`` at the call)."""

    DdeInitializeW: Numeric
    DdeInitializeA: Numeric
    DdeCreateStringHandleA: Handle
    DdeQueryStringA: Numeric
    DdeUninitialize: Numeric
    DdeCreateStringHandleW: Handle
    DdeFreeStringHandle: Numeric
    DdeQueryStringW: Numeric
    DdeNameService: Handle
    DdeCreateDataHandle: Handle
    DdeGetData: Numeric
    DdeFreeDataHandle: Numeric
    DdePostAdvise: Numeric
    DdeGetLastError: Numeric
    DdeConnect: Handle
    DdeDisconnect: Numeric
    DdeQueryConvInfo: Numeric
    DdeClientTransaction: Handle
    GetMessageW: Numeric
    PeekMessageW: Numeric
    TranslateMessage: Numeric
    DispatchMessageW: Numeric
    PostThreadMessageW: Numeric
    MsgWaitForMultipleObjects: Numeric
    GetWindowThreadProcessId: Numeric
    IsWindow: Numeric


class Kernel32(Protocol):
    """The kernel32 functions :func:`load_kernel32` declares."""

    GetCurrentThreadId: Numeric
    GetCurrentProcessId: Numeric
    GlobalAddAtomW: Numeric
    GlobalAlloc: Handle
    GlobalFree: Handle
    GlobalSize: Numeric
    GlobalLock: Handle
    GlobalUnlock: Numeric


def _declare(dll: object, name: str, restype: object, *argtypes: object) -> None:
    fn = getattr(dll, name)
    fn.restype, fn.argtypes = restype, list(argtypes)


def conv_info(u: User32, hconv: int) -> ConvInfo | None:  # pragma: no cover - Windows only
    """DdeQueryConvInfo(``hconv``, QID_SYNC): the conversation's CONVINFO, or None when DDEML no longer knows it."""
    info = ConvInfo()
    info.cb = ctypes.sizeof(ConvInfo)
    return info if u.DdeQueryConvInfo(hconv, QID_SYNC, ctypes.byref(info)) else None


def load_user32() -> User32:  # pragma: no cover - Windows only
    """user32 with the DDEML prototypes set; raises OSError off Windows."""
    if sys.platform != "win32":
        raise OSError("DDEML exists only on Windows")
    from ctypes import wintypes

    u = ctypes.WinDLL("user32", use_last_error=True)
    DWORD, UINT, HANDLE, LPVOID = wintypes.DWORD, wintypes.UINT, ctypes.c_void_p, ctypes.c_void_p
    _declare(u, "DdeInitializeW", UINT, ctypes.POINTER(DWORD), CALLBACK_TYPE, DWORD, DWORD)
    _declare(u, "DdeInitializeA", UINT, ctypes.POINTER(DWORD), CALLBACK_TYPE, DWORD, DWORD)
    _declare(u, "DdeCreateStringHandleA", HANDLE, DWORD, ctypes.c_char_p, ctypes.c_int)
    _declare(u, "DdeQueryStringA", DWORD, DWORD, HANDLE, ctypes.c_char_p, DWORD, ctypes.c_int)
    _declare(u, "DdeUninitialize", wintypes.BOOL, DWORD)
    _declare(u, "DdeCreateStringHandleW", HANDLE, DWORD, wintypes.LPCWSTR, ctypes.c_int)
    _declare(u, "DdeFreeStringHandle", wintypes.BOOL, DWORD, HANDLE)
    _declare(u, "DdeQueryStringW", DWORD, DWORD, HANDLE, wintypes.LPWSTR, DWORD, ctypes.c_int)
    _declare(u, "DdeNameService", HANDLE, DWORD, HANDLE, HANDLE, UINT)
    _declare(u, "DdeCreateDataHandle", HANDLE, DWORD, LPVOID, DWORD, DWORD, HANDLE, UINT, UINT)
    _declare(u, "DdeGetData", DWORD, HANDLE, LPVOID, DWORD, DWORD)
    _declare(u, "DdeFreeDataHandle", wintypes.BOOL, HANDLE)
    _declare(u, "DdePostAdvise", wintypes.BOOL, DWORD, HANDLE, HANDLE)
    _declare(u, "DdeGetLastError", UINT, DWORD)
    _declare(u, "DdeConnect", HANDLE, DWORD, HANDLE, HANDLE, LPVOID)
    _declare(u, "DdeDisconnect", wintypes.BOOL, HANDLE)
    _declare(u, "DdeQueryConvInfo", UINT, HANDLE, DWORD, ctypes.POINTER(ConvInfo))
    _declare(u, "DdeClientTransaction", HANDLE, LPVOID, DWORD, HANDLE, HANDLE, UINT, UINT, DWORD, ctypes.POINTER(DWORD))
    _declare(u, "GetMessageW", wintypes.BOOL, ctypes.POINTER(wintypes.MSG), wintypes.HWND, UINT, UINT)
    _declare(u, "PeekMessageW", wintypes.BOOL, ctypes.POINTER(wintypes.MSG), wintypes.HWND, UINT, UINT, UINT)
    _declare(u, "TranslateMessage", wintypes.BOOL, ctypes.POINTER(wintypes.MSG))
    _declare(u, "DispatchMessageW", ctypes.c_ssize_t, ctypes.POINTER(wintypes.MSG))
    _declare(u, "PostThreadMessageW", wintypes.BOOL, DWORD, UINT, wintypes.WPARAM, wintypes.LPARAM)
    _declare(u, "MsgWaitForMultipleObjects", DWORD, DWORD, LPVOID, wintypes.BOOL, DWORD, DWORD)
    _declare(u, "GetWindowThreadProcessId", DWORD, wintypes.HWND, ctypes.POINTER(DWORD))
    _declare(u, "IsWindow", wintypes.BOOL, wintypes.HWND)
    return cast(User32, u)


def load_kernel32() -> Kernel32:  # pragma: no cover - Windows only
    """kernel32 with the prototypes of the calls the transport makes; raises OSError off Windows."""
    if sys.platform != "win32":
        raise OSError("kernel32 exists only on Windows")
    from ctypes import wintypes

    k = ctypes.WinDLL("kernel32")
    _declare(k, "GetCurrentThreadId", wintypes.DWORD)
    _declare(k, "GetCurrentProcessId", wintypes.DWORD)
    _declare(k, "GlobalAddAtomW", wintypes.ATOM, wintypes.LPCWSTR)
    _declare(k, "GlobalAlloc", ctypes.c_void_p, wintypes.UINT, ctypes.c_size_t)
    _declare(k, "GlobalFree", ctypes.c_void_p, ctypes.c_void_p)
    _declare(k, "GlobalSize", ctypes.c_size_t, ctypes.c_void_p)
    _declare(k, "GlobalLock", ctypes.c_void_p, ctypes.c_void_p)
    _declare(k, "GlobalUnlock", wintypes.BOOL, ctypes.c_void_p)
    return cast(Kernel32, k)
