"""``DOPPLER ON|OFF`` is a table entry (issue 46): every face switches the radio's Doppler tuning with it, the
status word's tuning bit follows, it is in every face's help, and without a radio it is done with a warning.
Before, only the console's Ctrl+D could switch it, behind the table (TCP, web and DDE clients could not)."""

from __future__ import annotations

from nfwserver.commands.actions import DOPPLER_WITHOUT_RADIO
from nfwserver.commands.help_text import help_lines
from nfwserver.commands.table import Face
from nfwserver.config.schema import WebConfig
from nfwserver.core.status import StatusBit
from nfwserver.tcp.protocol import NovaTcpProtocol
from nfwserver.web.control import Control
from tests.dde.conftest import make_station

TOKEN = "doppler-token-0123"


def test_every_face_switches_doppler_and_the_core_records_it() -> None:
    station = make_station()
    core = station.core
    conv = station.system.connect("NFW32", "NFW_DATA")
    tcp = NovaTcpProtocol(core)
    web = Control(core, WebConfig(control=True, token=TOKEN), lambda host, line: True)
    assert core.tracker.status_word() & StatusBit.TUNING_DISABLED

    conv.poke("NFW_SERVER", "DOPPLER ON")  # DDE: acknowledged (a refusal raises)
    assert core.state.doppler_on and not core.tracker.status_word() & StatusBit.TUNING_DISABLED
    reply = tcp.handle("doppler off", "tcp 127.0.0.1:1")
    assert reply is not None and reply.lines == ("OK",) and not core.state.doppler_on
    answer = web.run({"command": "DOPPLER ON", "token": TOKEN}, "web 127.0.0.1")
    assert answer.ok and core.state.doppler_on
    result = core.command("DOPPLER OFF", source="console", face=Face.CONSOLE)
    assert result.ok and not core.state.doppler_on

    recorded = [(e.client, e.text, e.accepted) for e in core.events.recent() if e.kind == "poke"]
    assert recorded[-4:] == [("conv 1 NFW32/NFW_DATA", "DOPPLER ON", True), ("tcp 127.0.0.1:1", "doppler off", True),
                             ("web 127.0.0.1", "DOPPLER ON", True), ("console", "DOPPLER OFF", True)]
    for face in (Face.TCP, Face.CONSOLE):
        assert any(line.startswith("DOPPLER ON|OFF ") for line in help_lines(face))


def test_doppler_on_without_a_radio_is_done_with_a_warning() -> None:
    station = make_station()
    station.core.radio_configured = False
    reply = NovaTcpProtocol(station.core).handle("DOPPLER ON", "tcp 127.0.0.1:1")
    assert reply is not None and reply.lines == (f"OK warning: {DOPPLER_WITHOUT_RADIO}",)
    assert station.core.state.doppler_on
    reply = NovaTcpProtocol(station.core).handle("DOPPLER MAYBE", "tcp 127.0.0.1:1")
    assert reply is not None and reply.lines == ("ERROR DOPPLER needs ON or OFF",)
