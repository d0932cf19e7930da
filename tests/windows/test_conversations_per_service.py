"""Issue 23 item 4: one client instance holding a conversation with ``NFW32`` opens a second one with
``NFW_SERVER`` (same topic).  The station must accept every sequence of connects that the smallest DDEML
server (``minimal_ddeml_server.py``, serving two other names beside it) accepts, and be refused only
where that server is refused too.

Runs where DDEML exists: under Wine via ``tools/wine/test`` (CI), or on Windows.
"""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Iterable
from pathlib import Path

import pytest

from tests.waiting import wait_for
from tests.windows.conftest import NOVA, wine_version

pytestmark = [
    pytest.mark.windows,
    pytest.mark.skipif(sys.platform != "win32", reason="needs Windows DDEML"),
]

HERE = Path(__file__).resolve().parent


MINIMAL = ("MIN32", "MIN_SERVER")  #: the minimal server's names (a connect to a name both served reaches both)


@pytest.fixture(scope="module")
def minimal_server(tmp_path_factory):
    ready = tmp_path_factory.mktemp("minimal") / "ready"
    proc = subprocess.Popen([sys.executable, str(HERE / "minimal_ddeml_server.py"), "--seconds", "300",
                             "--ready", str(ready), "--services", ",".join(MINIMAL)],
                            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        def up() -> bool:
            assert proc.poll() is None, proc.poll()
            return ready.exists()

        wait_for(up, 60.0, "the minimal DDEML server to register its services", interval_s=0.1)
        yield proc
    finally:
        proc.kill()
        proc.wait(10)


def _connects(services: Iterable[str]) -> list[bool]:
    """One fresh client instance connects to each of ``services`` in turn (topic NFW_DATA), keeping every
    conversation and requesting on each; which connects succeeded."""
    from nfwserver.dde.ddeml_client import DdemlClient, DdeRefused

    client = DdemlClient()
    got = []
    try:
        for service in services:
            try:
                conv = client.connect(service, "NFW_DATA")
            except DdeRefused:
                got.append(False)
                continue
            got.append(bool(NOVA.match(client.request_text(conv, "NFW_SERVER"))))
    finally:
        client.close()
    return got


def test_a_second_conversation_on_the_other_service_name_works_while_the_first_streams(station) -> None:
    from nfwserver.dde.ddeml_client import DdemlClient

    client = DdemlClient()
    try:
        first = client.connect("NFW32", "NFW_DATA")
        client.poke(first, "NFW_SERVER", "TUNE ON")
        client.start_advise(first, "NFW_SERVER", hot=True)
        assert client.pump(5.0, until=lambda: client.advise_counts[first] >= 3)
        second = client.connect("NFW_SERVER", "NFW_DATA")  # refused, issue 23 item 4 said
        assert NOVA.match(client.request_text(second, "NFW_SERVER"))
        client.start_advise(second, "NFW_DATA", hot=True)
        before = client.advise_counts[first]
        assert client.pump(5.0, until=lambda: client.advise_counts[second] >= 3
                           and client.advise_counts[first] >= before + 3)
        assert NOVA.match(client.request_text(first, "NFW_SERVER"))  # the first goes on as before
    finally:
        client.close()


@pytest.mark.parametrize("shape", [(0, 1), (1, 0), (0, 1, 0), (0, 0)])
def test_the_station_accepts_the_connects_a_minimal_ddeml_server_accepts(station, minimal_server, shape) -> None:
    nova = _connects(["NFW32", "NFW_SERVER"][i] for i in shape)
    minimal = _connects([MINIMAL[i] for i in shape])
    assert nova == minimal
    assert nova[:2] == [True, shape[1] != shape[0] or wine_version() is None]
    # Under Wine a second conversation to the same service and topic from one instance never reaches any
    # server: Wine's DdeConnect finds the first and returns NULL ("This Conv already exists"), with no
    # error code.  Windows allows it.


def _pywin32_connects(services: Iterable[str]) -> list[bool]:
    """As :func:`_connects`, through pywin32's ``dde`` module (one server object, a conversation each)."""
    import win32ui  # noqa: F401  (pywin32's dde module refuses to load before win32ui)
    import dde  # isort: skip

    server = dde.CreateServer()
    server.Create("probe")
    got, convs = [], []
    try:
        for service in services:
            conv = dde.CreateConversation(server)
            try:
                conv.ConnectTo(service, "NFW_DATA")
            except dde.error:  # "ConnectTo failed"
                got.append(False)
                continue
            convs.append(conv)
            got.append(True)
    finally:
        server.Destroy()
    return got


@pytest.mark.parametrize("shape", [(0, 1), (0, 0)])
def test_pywin32_gets_the_same_answers_from_the_station_and_the_minimal_server(station, minimal_server,
                                                                                shape) -> None:
    """pywin32 (MATLAB's route): a conversation per service name; a second one to the same name is
    refused under Wine by either server alike (Wine's client side, see above), so it is not ours."""
    nova = _pywin32_connects(["NFW32", "NFW_SERVER"][i] for i in shape)
    assert nova == _pywin32_connects([MINIMAL[i] for i in shape])
    assert nova == [True, shape[1] != shape[0] or wine_version() is None]
