"""Real DDE on Windows: the server on the DDEML transport, talked to as legacy clients do.

Skipped on other operating systems; the GitHub Actions workflow runs it on windows-latest.
"""

from __future__ import annotations

import re
import sys

import pytest

pytestmark = [
    pytest.mark.windows,
    pytest.mark.skipif(sys.platform != "win32", reason="needs Windows DDEML"),
]

NOVA = re.compile(r"^\S{1,12} AZ:\d{1,3}\.\d EL:-?\d{1,2}\.\d RR:-?\d+\.\d{10} AH:[YN]$")


@pytest.fixture
def live_server():
    from nfwserver.clock import SystemClock
    from nfwserver.core.publisher import Publisher
    from nfwserver.core.station_core import StationCore
    from nfwserver.dde.nova_service import NovaDdeService
    from nfwserver.dde.windows_transport import WindowsDdeTransport
    from tests.dde.conftest import CATALOG, ISS, OBSERVER

    core = StationCore(CATALOG, OBSERVER, SystemClock(), satellite=ISS, rate_hz=10)
    server = NovaDdeService(core)
    transport = WindowsDdeTransport()
    server.attach(transport)
    publisher = Publisher(core, SystemClock())
    publisher.start()
    yield core
    publisher.stop()
    server.detach()
    transport.close()


def test_ddeml_client_poke_request_hot_and_warm_advise(live_server) -> None:
    from nfwserver.dde.ddeml_client import DdemlClient

    client = DdemlClient()
    try:
        conv = client.connect("NFW32", "NFW_DATA")
        assert client.request_text(conv, "NFW_SERVER") == ""
        client.poke(conv, "NFW_SERVER", "TUNE ON")
        client.pump(0.3)
        assert NOVA.match(client.request_text(conv, "NFW_SERVER"))
        client.start_advise(conv, "NFW_SERVER", hot=True)
        client.pump(1.0)
        hot = [d for item, d in client.received if d is not None]
        assert len(hot) >= 5 and all(NOVA.match(d.rstrip(b"\x00").decode("cp1252")) for d in hot)
        client.stop_advise(conv, "NFW_SERVER")
        client.received.clear()
        client.start_advise(conv, "NFW_DATA", hot=False)
        client.pump(0.6)
        assert client.received and all(d is None for _, d in client.received)
        with pytest.raises(OSError):
            client.poke(conv, "NFW_SERVER", "SAT=99999")  # unknown satellite: DDE_FNOTPROCESSED
        other = next(s for s in live_server.catalog if s.catalog_number != 25544)
        client.poke(conv, "NFW_SERVER", f"SAT={other.catalog_number}")
        client.pump(0.3)
        assert client.request_text(conv, "NFW_SERVER").startswith(other.dde_name + " ")
        client.disconnect(conv)
    finally:
        client.close()


def test_pywin32_dde_conversation(live_server) -> None:
    import dde  # pywin32
    import win32ui  # noqa: F401  (initialises the MFC support pywin32's dde module needs)

    server = dde.CreateServer()
    server.Create("nfwtest")
    try:
        conv = dde.CreateConversation(server)
        conv.ConnectTo("NFW32", "NFW_DATA")
        conv.Poke("NFW_SERVER", "TUNE ON")
        import time

        time.sleep(0.3)
        assert NOVA.match(conv.Request("NFW_SERVER").rstrip("\x00"))
    finally:
        server.Destroy()
