"""A Windows program: the smallest DDEML server for Nova's names, to compare our transport with.

``python minimal_ddeml_server.py --seconds S --ready FILE [--services A,B]``: one ``DdeInitializeW``
instance registers both service names (default ``NFW32``, ``NFW_SERVER``), accepts ``XTYP_CONNECT`` for
topic ``NFW_DATA`` and answers a request on any item with a fixed Nova string; nothing else.  It is what
issue 23 item 4 compared the station against (there in C; these are the same DDEML calls).  ``FILE`` is
created once the names are registered.  Other names let it run beside a station: a client's
``DdeConnect`` to a name both served would reach both.
"""

from __future__ import annotations

import argparse
import ctypes
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent.parent))

from nfwserver.dde import ddeml  # noqa: E402

TEXT = b"MINIMAL AZ:1.0 EL:2.0 RR:0.0000000000 AH:Y\x00"


def main(argv: list[str] | None = None) -> int:
    from ctypes import wintypes

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--ready", required=True)
    parser.add_argument("--services", default="NFW32,NFW_SERVER")
    args = parser.parse_args(argv)
    u = ddeml.load_user32()
    inst = wintypes.DWORD(0)

    def topic(hsz: int) -> str:
        buf = ctypes.create_unicode_buffer(256)
        u.DdeQueryStringW(inst.value, hsz, buf, 256, ddeml.CP_WINUNICODE)
        return buf.value

    def callback(utype, fmt, hconv, hsz1, hsz2, hdata, data1, data2):
        if utype == ddeml.XTYP_CONNECT:
            return 1 if topic(hsz1).upper() == "NFW_DATA" else 0
        if utype == ddeml.XTYP_REQUEST:
            buf = ctypes.create_string_buffer(TEXT, len(TEXT))
            return u.DdeCreateDataHandle(inst.value, buf, len(TEXT), 0, hsz2, fmt, 0)
        return 0

    keep = ddeml.CALLBACK_TYPE(callback)
    if u.DdeInitializeW(ctypes.byref(inst), keep, ddeml.APPCLASS_STANDARD, 0) != ddeml.DMLERR_NO_ERROR:
        return 1
    for name in args.services.split(","):
        if not u.DdeNameService(inst.value, u.DdeCreateStringHandleW(inst.value, name, ddeml.CP_WINUNICODE),
                                None, ddeml.DNS_REGISTER):
            return 1
    Path(args.ready).write_text("up\n")
    msg = wintypes.MSG()
    end = time.monotonic() + args.seconds
    while time.monotonic() < end:
        while u.PeekMessageW(ctypes.byref(msg), None, 0, 0, ddeml.PM_REMOVE):
            u.TranslateMessage(ctypes.byref(msg))
            u.DispatchMessageW(ctypes.byref(msg))
        u.MsgWaitForMultipleObjects(0, None, False, 50, ddeml.QS_ALLINPUT)
    u.DdeUninitialize(inst.value)
    return 0


if __name__ == "__main__":
    sys.exit(main())
