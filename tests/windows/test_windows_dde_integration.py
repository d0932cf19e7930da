"""Real DDE: the server core on the DDEML transport in this process, with real DDEML clients.

Runs where DDEML exists: under Wine via ``tools/wine/test`` (CI), or on Windows.
"""

from __future__ import annotations

import sys

import pytest

from tests.waiting import wait_for
from tests.windows.conftest import NOVA, request_after_refusal

pytestmark = [
    pytest.mark.windows,
    pytest.mark.skipif(sys.platform != "win32", reason="needs Windows DDEML"),
]


def test_ddeml_client_poke_request_hot_and_warm_advise(live_server) -> None:
    from nfwserver.dde.ddeml_client import DdemlClient, DdeRefused

    client = DdemlClient()
    try:
        conv = client.connect("NFW32", "NFW_DATA")
        assert client.request_text(conv, "NFW_SERVER") == ""  # before TUNE ON: empty, not refused
        client.poke(conv, "NFW_SERVER", "TUNE ON")
        client.pump(0.3)
        assert NOVA.match(client.request_text(conv, "NFW_SERVER"))
        client.start_advise(conv, "NFW_SERVER", hot=True)
        client.pump(1.0)
        hot = [d for item, d in client.received if d is not None]
        assert len(hot) >= 8 and all(NOVA.match(d.rstrip(b"\x00").decode("cp1252")) for d in hot)
        client.stop_advise(conv, "NFW_SERVER")
        client.received.clear()
        client.start_advise(conv, "NFW_DATA", hot=False)
        client.pump(0.6)
        assert len(client.received) >= 4 and all(d is None for _, d in client.received)
        with pytest.raises(DdeRefused):
            client.poke(conv, "NFW_SERVER", "SAT=99999")  # unknown satellite: not acknowledged
        other = next(s for s in live_server.catalog if s.catalog_number != 25544)
        client.poke(conv, "NFW_SERVER", f"SAT={other.catalog_number}")
        client.pump(0.3)
        assert request_after_refusal(client, conv, "NFW_SERVER").startswith(other.dde_name + " ")
        client.disconnect(conv)
    finally:
        client.close()


@pytest.mark.parametrize("ansi", [False, True], ids=["unicode-client", "ansi-client"])
def test_execute_reaches_the_server_whole(live_server, ansi: bool) -> None:
    """DDEML hands executes to our DdeInitializeW instance as UTF-16, also from ANSI clients."""
    from nfwserver.dde.ddeml_client import DdemlClient

    client = DdemlClient(ansi=ansi)
    try:
        conv = client.connect("NFW_SERVER", "NFW_DATA")
        assert not live_server.snapshot().state.tracking
        client.execute(conv, "TRACK ON")
        assert live_server.snapshot().state.tracking
        client.execute(conv, "TRACK OFF")
        assert not live_server.snapshot().state.tracking
        client.disconnect(conv)
    finally:
        client.close()


def test_pywin32_dde_conversation(live_server) -> None:
    import win32ui  # noqa: F401  (pywin32's dde module refuses to load before win32ui)
    import dde  # isort: skip

    server = dde.CreateServer()
    server.Create("nfwtest")
    try:
        conv = dde.CreateConversation(server)
        conv.ConnectTo("NFW32", "NFW_DATA")
        conv.Poke("NFW_SERVER", "TUNE ON")
        wait_for(lambda: live_server.snapshot().state.feed_on, 3.0, "the station to apply TUNE ON", interval_s=0.02)
        assert NOVA.match(conv.Request("NFW_SERVER").rstrip("\x00"))
        conv.Exec("TRACK ON")
        # pywin32's Exec can return before the server's DDE thread has handled the execute under Wine
        # (seen once in CI): allow the station up to 3 s of real DDE time to apply it.
        wait_for(lambda: live_server.snapshot().state.tracking, 3.0, "the station to apply TRACK ON",
                 interval_s=0.02)
    finally:
        server.Destroy()


def test_failures_on_the_dde_thread_reach_the_caller() -> None:
    from nfwserver.dde.windows_transport import WindowsDdeTransport

    transport = WindowsDdeTransport()
    try:
        with pytest.raises(OSError, match="could not register"):
            transport.register_service("", object())  # DDEML refuses to register an empty name
    finally:
        transport.close()
    with pytest.raises(OSError):
        transport.register_service("NFW32", object())  # the DDE thread has stopped


def test_default_transport_is_real_ddeml_here() -> None:
    from nfwserver.app.platform_transport import default_transport
    from nfwserver.dde.windows_transport import WindowsDdeTransport

    transport, note = default_transport()
    try:
        assert isinstance(transport, WindowsDdeTransport) and note == "serving real DDE (DDEML)"
    finally:
        transport.close()


def _atom_references(name: str) -> int:
    """Reference count of the global atom ``name`` (0 when there is none: DDEML's string handles are
    local atoms, made global for the messages that carry them), read with ntdll's
    ``NtQueryInformationAtom`` (AtomBasicInformation: USHORT ReferenceCount first)."""
    import ctypes
    from ctypes import wintypes

    atom = ctypes.WinDLL("kernel32").GlobalFindAtomW(name)
    if not atom:
        return 0
    buffer = ctypes.create_string_buffer(512)
    ntdll = ctypes.WinDLL("ntdll")
    ntdll.NtQueryInformationAtom.argtypes = [wintypes.WORD, ctypes.c_int, ctypes.c_void_p, wintypes.ULONG,
                                             ctypes.POINTER(wintypes.ULONG)]
    status = ntdll.NtQueryInformationAtom(atom, 0, buffer, len(buffer), None)
    assert status == 0, f"NtQueryInformationAtom: 0x{status & 0xFFFFFFFF:08X}"
    return ctypes.c_ushort.from_buffer(buffer).value


def test_publishing_leaves_the_item_atoms_reference_counts_steady(live_server) -> None:
    """Every tick posts both items.  On the one with a hot link, every atom reference taken for a post is
    released by the client that takes the data (under Wine, with the references the transport adds); the
    one nobody advises on is not handed to DdePostAdvise at all (Wine's would leak one reference a call)."""
    from nfwserver.dde.ddeml_client import DdemlClient

    client = DdemlClient()
    try:
        conv = client.connect("NFW32", "NFW_DATA")
        client.poke(conv, "NFW_SERVER", "TUNE ON")
        client.start_advise(conv, "NFW_SERVER", hot=True)
        client.pump(0.5)
        before = {name: _atom_references(name) for name in ("NFW_DATA", "NFW_SERVER")}
        client.received.clear()
        client.pump(2.0)  # about 20 ticks, each posting NFW_SERVER (linked) and NFW_DATA (not linked)
        assert len([d for _, d in client.received if d]) >= 15
        after = {name: _atom_references(name) for name in ("NFW_DATA", "NFW_SERVER")}
        assert after["NFW_DATA"] == before["NFW_DATA"], (before, after)
        assert abs(after["NFW_SERVER"] - before["NFW_SERVER"]) <= 1, (before, after)  # one post may be in flight
        client.disconnect(conv)
    finally:
        client.close()
