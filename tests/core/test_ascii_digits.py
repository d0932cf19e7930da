"""Numbers from outside are ASCII digits only (issue 23 item 13), on every face that takes one.

``"²".isdigit()`` is true in Python but ``int("²")`` raises, and ``int("٣")`` (Arabic-Indic three) is 3:
before this, ``SAT=²`` escaped as a ValueError (a DDE traceback; the console exited) and other scripts'
digits were accepted.  Each face now refuses them with the same clear reason and keeps serving.
"""

from __future__ import annotations

import argparse
import asyncio

import pytest

from nfwserver.cli.arguments import time_value
from nfwserver.commands.parsing import parse_request
from nfwserver.commands.table import Face
from nfwserver.console.app import NfwConsole
from nfwserver.dialects.predict_listing import atol
from nfwserver.fake_dde import DdeError
from nfwserver.tracking.elements import load_elements
from tests.app.console_helpers import log_text, searched, settle
from tests.dde.conftest import ISS, make_station
from tests.tcp.conftest import LOOPBACK_ONLY, LineClient

#: Superscript two, Arabic-Indic three, a fullwidth 5, Devanagari one, a circled one, an ISS number in
#: Arabic-Indic digits, and a mix.
NOT_ASCII = ["²", "٣", "５", "१", "①", "٢٥٥٤٤", "2554٤"]


@pytest.mark.parametrize("value", NOT_ASCII)
@pytest.mark.parametrize("command", ["SAT", "ANTAZ", "ANTEL"])
def test_the_grammar_refuses_digits_other_than_ascii(command: str, value: str) -> None:
    refused = parse_request(f"{command}={value}", Face.DDE).error
    assert refused is not None and refused.bad_argument
    assert ("catalog number" if command == "SAT" else "number of degrees") in str(refused)


@pytest.mark.parametrize("value", ["²", "٢٥٥٤٤"])
def test_a_dde_poke_is_refused_and_the_feed_goes_on(value: str) -> None:
    station = make_station()
    conv = station.system.connect("NFW32", "NFW_DATA")
    conv.poke("NFW_SERVER", "TUNE ON")
    station.run(1.0)
    with pytest.raises(DdeError):
        conv.poke("NFW_SERVER", f"SAT={value}")
    before = conv.request_text("NFW_SERVER")
    station.run(1.0)
    assert station.core.state.catalog_number == ISS
    assert conv.request_text("NFW_SERVER").startswith("ISS ") and before.startswith("ISS ")
    refused = [e for e in station.core.events.recent() if e.kind == "poke" and e.accepted is False]
    assert refused and "catalog number" in refused[-1].detail


def test_a_tcp_command_is_refused_and_the_connection_keeps_serving() -> None:
    from nfwserver.tcp.server import NovaTcpServer

    station = make_station()
    server = NovaTcpServer(station.core, LOOPBACK_ONLY)
    server.start()
    client = LineClient(server.address)
    try:
        client.read_line()  # greeting
        client.send("SAT=²\r\n".encode())
        reply = client.text()
        assert reply.startswith("ERR") and "catalog number" in reply
        assert client.ask("TUNE ON") == "OK"
        assert station.core.state.catalog_number == ISS
    finally:
        client.close()
        server.stop()


def test_the_console_refuses_the_poke_and_its_picker_searches_without_crashing() -> None:
    station = make_station()

    async def scenario() -> None:
        app = NfwConsole(station.core, favourites=(ISS,))
        async with app.run_test(size=(100, 30)) as pilot:
            await settle(app, pilot, until=lambda: searched(app), what="the first pass search")
            await pilot.press(*"SAT=²", "enter")
            await settle(app, pilot, until=lambda: "REFUSED" in log_text(app, "incoming"))
            assert "REFUSED (SAT needs a catalog number, got '\\xb2')" in " ".join(log_text(app, "incoming").split())
            await pilot.press("f2", "²")
            await settle(app, pilot, until=lambda: type(app.screen).__name__ == "SatellitePicker")
            await pilot.press("escape")
            await pilot.pause()
            assert app.is_running and station.core.state.catalog_number == ISS

    asyncio.run(scenario())


def test_predict_reads_a_number_as_c_atol_does() -> None:
    assert atol(" 25544") == 25544
    assert atol("²") == 0 and atol("٢٥٥٤٤") == 0 and atol("12٣") == 12


def test_relative_start_times_take_ascii_digits_only() -> None:
    with pytest.raises(argparse.ArgumentTypeError):
        time_value("+²h")
    with pytest.raises(argparse.ArgumentTypeError):
        time_value("+٣h")


def test_an_amsat_set_with_other_digits_is_rejected_not_read_as_numbers() -> None:
    block = ("Satellite: TEST\nCatalog number: ٢٥٥٤٤\nEpoch time: 26128.5\nElement set: 999\n"
             "Inclination: 51.6 deg\nRA of node: 100.0 deg\nEccentricity: 0.0005\nArg of perigee: 90.0 deg\n"
             "Mean anomaly: 270.0 deg\nMean motion: 15.5 rev/day\nDecay rate: 0.0 rev/day^2\n"
             "Epoch rev: 1000\nChecksum: 300\n")
    result = load_elements(block, "amsat")
    assert not result.sets and result.rejected
