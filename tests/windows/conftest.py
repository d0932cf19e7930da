"""Fixtures of the Windows suite: a station process serving real DDE, and an in-process server.

These run only where DDEML exists (Windows, or the Windows Python under Wine: ``tools/wine/test``).
"""

from __future__ import annotations

import contextlib
import re
import sys
from collections.abc import Callable, Iterator
from typing import TypeVar

import pytest

T = TypeVar("T")

#: Nova's DDE string, from the spec's own words: name, AZ/EL one decimal, RR ten decimals, AH Y/N.
NOVA = re.compile(r"^\S{1,12} AZ:\d{1,3}\.\d EL:-?\d{1,2}\.\d RR:-?\d+\.\d{10} AH:[YN]$")


def wine_version() -> str | None:
    """Wine's version when running under Wine (ntdll exports ``wine_get_version``), else None."""
    if sys.platform != "win32":
        return None
    import ctypes

    ntdll = ctypes.WinDLL("ntdll")
    if not hasattr(ntdll, "wine_get_version"):
        return None
    ntdll.wine_get_version.restype = ctypes.c_char_p
    return ntdll.wine_get_version().decode()


def request_after_refusal(client, conv: int, item: str) -> str:
    """The first request after a refused transaction.  Wine 8.0's DDEML may fail that one request
    with DMLERR_NOTPROCESSED while an advise loop is active (docs/PLATFORMS.md); on Windows it
    must succeed at once."""
    from nfwserver.dde.ddeml_client import DdeRefused

    try:
        return client.request_text(conv, item)
    except DdeRefused:
        if wine_version() is None:
            raise
        return client.request_text(conv, item)


def on_linked_item(client, transaction: Callable[[], T], tries: int = 3) -> T:
    """Run ``transaction()``: a poke or request on an item the same conversation holds a warm advise
    link on.  Wine 8.0's client DDEML may take the link's own ``WM_DDE_DATA`` notification (no data),
    when it arrives while the transaction waits, for the transaction's answer: a poke then reports
    result 0 though the server acknowledged it (``WDML_HandlePokeReply`` in Wine's ``dde_client.c``
    tests ``!= WM_DDE_ACK && wrong window`` where ``||`` is meant, and the item matches), a request
    gets a NULL handle (docs/PLATFORMS.md).  Under Wine a transaction reported refused is run again
    once the late answer has been dispatched, up to ``tries`` times, each try needing a proper
    answer; on Windows the first answer counts."""
    from nfwserver.dde.ddeml_client import DdeRefused

    attempts = tries if wine_version() is not None else 1
    for attempt in range(attempts):
        try:
            return transaction()
        except DdeRefused:
            if attempt == attempts - 1:
                raise
            client.pump(0.2)  # the real answer arrives now, with no transaction waiting for it
    raise AssertionError("unreachable")


@pytest.fixture(scope="session")
def station(tmp_path_factory):
    """``nfwserver run --headless`` in another process, serving NFW32 and NFW_SERVER (ISS, 10 Hz)."""
    if sys.platform != "win32":
        pytest.skip("needs Windows DDEML")
    from tests.windows.station_config import write_station_config
    from tests.windows.station_process import StationProcess

    base = tmp_path_factory.mktemp("station")
    proc = StationProcess(write_station_config(base), duration_s=600, log_file=base / "station.log")
    try:
        proc.wait_serving()
        yield proc
    finally:
        proc.stop()


@contextlib.contextmanager
def serving_station(services: tuple[str, ...] | None = None) -> Iterator:
    """A server core on the DDEML transport in this process, publishing at 10 Hz (ISS); yields the
    Nova DDE service (``services`` its DDE service names, Nova's by default)."""
    from nfwserver.clock import SystemClock
    from nfwserver.core.publisher import Publisher
    from nfwserver.core.station_core import StationCore
    from nfwserver.dde.nova_service import NovaDdeService
    from nfwserver.dde.windows_transport import WindowsDdeTransport
    from tests.dde.conftest import CATALOG, ISS, OBSERVER

    core = StationCore(CATALOG, OBSERVER, SystemClock(), satellite=ISS, rate_hz=10)
    server = NovaDdeService(core) if services is None else NovaDdeService(core, services=services)
    transport = WindowsDdeTransport()
    server.attach(transport)
    publisher = Publisher(core, SystemClock())
    publisher.start()
    try:
        yield server
    finally:
        publisher.stop()
        server.detach()
        transport.close()


@pytest.fixture
def live_server():
    """A server core on the DDEML transport in this process (for checks of its state)."""
    with serving_station() as server:
        yield server.core
