"""Wine's ``DdePostAdvise`` leaks one moveable global handle per hot link and post to another process
(docs/PLATFORMS.md); the transport frees those copies, so a long-running station keeps its handles.

Runs under Wine only (``tools/wine/test``): the leak is Wine's, and counting free moveable handles by
taking them all relies on kernelbase's fixed table of 65,536.
"""

from __future__ import annotations

import ctypes
import json
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.windows.conftest import serving_station, wine_version

pytestmark = [
    pytest.mark.windows,
    pytest.mark.skipif(sys.platform != "win32", reason="needs Windows DDEML"),
]

CLIENTS = Path(__file__).resolve().parent / "dde_clients.py"


def pump_messages(seconds: float) -> None:
    """Dispatch this thread's window messages for ``seconds``: DdeConnect in the client program sends
    WM_DDE_INITIATE to every top-level window, windows this thread kept from earlier tests included,
    and waits for each to answer."""
    from ctypes import wintypes

    from nfwserver.dde import ddeml

    user32 = ddeml.load_user32()
    msg = wintypes.MSG()
    deadline = time.monotonic() + seconds
    while True:
        while user32.PeekMessageW(ctypes.byref(msg), None, 0, 0, ddeml.PM_REMOVE):
            user32.TranslateMessage(ctypes.byref(msg))
            user32.DispatchMessageW(ctypes.byref(msg))
        remaining_ms = int((deadline - time.monotonic()) * 1000)
        if remaining_ms <= 0:
            return
        user32.MsgWaitForMultipleObjects(0, None, False, min(remaining_ms, 20), ddeml.QS_ALLINPUT)


def free_moveable_handles(limit: int = 70_000) -> int:
    """How many ``GlobalAlloc(GMEM_MOVEABLE)`` calls succeed in this process right now (all freed again)."""
    kernel32 = ctypes.WinDLL("kernel32")
    kernel32.GlobalAlloc.restype, kernel32.GlobalAlloc.argtypes = ctypes.c_void_p, [ctypes.c_uint, ctypes.c_size_t]
    kernel32.GlobalFree.restype, kernel32.GlobalFree.argtypes = ctypes.c_void_p, [ctypes.c_void_p]
    taken = []
    while len(taken) < limit:
        handle = kernel32.GlobalAlloc(0x0002, 16)
        if not handle:
            break
        taken.append(handle)
    for handle in taken:
        kernel32.GlobalFree(handle)
    return len(taken)


# Names of their own (the suite's other stations serve NFW32 and NFW_SERVER); two, because Wine allows
# one conversation per service and program.
SERVICES = ("NFW_HANDLES_A", "NFW_HANDLES_B")


@pytest.fixture
def own_station():
    """A server core on the DDEML transport in this process, under service names nobody else serves."""
    with serving_station(SERVICES) as server:
        yield server


def test_hot_links_from_another_process_leave_the_stations_moveable_handles(own_station, tmp_path) -> None:
    if wine_version() is None:
        pytest.skip("the leak and the handle table are Wine's")
    before = free_moveable_handles()
    assert before < 70_000  # the table is finite, so the count means something
    out = tmp_path / "clients.json"
    # Two conversations in another process, hot on NFW_SERVER for 4 s: about 80 posts plus those while
    # they connect.  Each leaked copy would take one handle for good.
    program = subprocess.Popen([sys.executable, str(CLIENTS), "--clients", "2", "--seconds", "4",
                                "--services", ",".join(SERVICES), "--out", str(out)],
                               stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    links_seen = 0
    try:
        while program.poll() is None:
            links_seen = max(links_seen, own_station.client_count()[1])
            pump_messages(0.1)
    finally:
        if program.poll() is None:
            program.kill()
    assert program.returncode == 0 and links_seen == 2, (program.returncode, links_seen)
    after = free_moveable_handles()
    records = json.loads(out.read_text())
    carried = records[0]["program_deliveries"]
    assert all(r["error"] is None for r in records), records
    assert carried["string"] >= 60 and carried["no data"] == 0, carried
    assert before - after <= 5, (before, after, carried)  # without the transport's freeing: >= 60
