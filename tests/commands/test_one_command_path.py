"""One path for a command (issue 36 item 1): a face parses what it received once, the core runs the entry's
action from the table, and every face's replies are what they were (the wire does not change)."""

from __future__ import annotations

import asyncio
from collections import Counter
from pathlib import Path

import pytest

from nfwserver.commands.parsing import Request
from nfwserver.commands.table import Command, Face
from nfwserver.console.app import NfwConsole
from nfwserver.tcp.protocol import NovaTcpProtocol
from tests.app.console_helpers import searched, settle
from tests.dde.conftest import make_station

ROOT = Path(__file__).resolve().parents[2]

#: TCP lines and the replies 6ca6bee gave them (read from that commit's protocol, one per line).
REPLIES = [
    ("SAT=25544", "OK"),
    ("sat = iss", "OK"),
    ("SAT=99999", "ERROR satellite 99999 is not in the catalog; keeping the current one"),
    ("SAT=\u0662", "ERROR SAT needs a catalog number, got '\\u0662'"),
    ("TUNE", "ERROR TUNE needs ON or OFF"),
    ("BOGUS", "ERROR not a Nova command (TUNE ON|OFF, TRACK ON|OFF, SAT=n, ANTAZ=deg, ANTEL=deg)"),
    ("TRACK ON", "OK warning: TRACK ON with no rotor configured: nothing turns here ([rotor] backend); DDE "
                 "clients that drive their own rotor still follow the feed"),
    ("ANTAZ=721", "ERROR ANTAZ 721.0 is outside -360..720 degrees"),
    ("FLIP ON", "ERROR no rotor is configured"),
    ("FLIP sideways", "ERROR no rotor is configured"),
    ("PARK", "ERROR no rotor is configured"),
    ("HELP me", "ERROR HELP needs nothing after it"),
    ("QUIT now", "ERROR QUIT needs nothing after it"),
    ("x" * 300, "ERROR poke of 300 characters is too long"),
    ("QUIT", "OK"),
]


def test_tcp_replies_are_those_of_6ca6bee() -> None:
    station = make_station()
    station.core.rotor_configured = False
    protocol = NovaTcpProtocol(station.core)
    got = []
    for line, _ in REPLIES:
        reply = protocol.handle(line, "tcp 127.0.0.1:1")
        assert reply is not None
        got.append((line, "\r\n".join(reply.lines)))
    assert got == REPLIES


def test_a_tcp_line_is_parsed_once(monkeypatch) -> None:
    """Each entry's grammar is tried at most once on a line (6ca6bee parsed a station command twice: in the
    TCP face, then again in the core)."""
    tried: Counter[tuple[str, str]] = Counter()
    original = Command.match

    def counting(self: Command, text: str):
        tried[(self.word, text)] += 1
        return original(self, text)

    monkeypatch.setattr(Command, "match", counting)
    station = make_station()
    protocol = NovaTcpProtocol(station.core)
    for line in ("SAT=25544", "TUNE ON", "ANTAZ=12", "SAT=99999", "BOGUS", "STATUS", "FLIP ON"):
        protocol.handle(line, "tcp 127.0.0.1:1")
    assert tried and max(tried.values()) == 1, [key for key, n in tried.items() if n > 1]


def test_the_console_sends_every_command_as_the_console_through_the_core(monkeypatch) -> None:
    """Its TUNE key and its FLIP key go the way a typed command goes (6ca6bee sent TUNE as a DDE poke and set
    the flip mode on the rotor behind the table's back)."""
    station = make_station()
    core = station.core
    sent: list[tuple[str, Face]] = []
    execute, command = core.execute if hasattr(core, "execute") else None, core.command

    def record_execute(request: Request, *args, **kwargs):
        sent.append((request.text, request.face))
        return execute(request, *args, **kwargs)

    def record_command(text: str, *args, face: Face = Face.DDE, **kwargs):
        sent.append((text, face))
        return command(text, *args, face=face, **kwargs)

    monkeypatch.setattr(core, "execute", record_execute, raising=False)
    monkeypatch.setattr(core, "command", record_command)

    async def scenario() -> None:
        app = NfwConsole(core)
        async with app.run_test(size=(120, 40)) as pilot:
            await settle(app, pilot, until=lambda: searched(app), what="the first pass search")
            await pilot.press("ctrl+t")
            await pilot.press("ctrl+f")
            await pilot.press(*"TUNE OFF", "enter")
            await settle(app, pilot, until=lambda: len(sent) >= 3)

    asyncio.run(scenario())
    assert sent == [("TUNE ON", Face.CONSOLE), ("FLIP auto", Face.CONSOLE), ("TUNE OFF", Face.CONSOLE)]


def test_the_no_rotor_reason_is_written_once() -> None:
    """Every face says why a rotor command is refused in the words of one constant."""
    holders = [path.relative_to(ROOT).as_posix() for path in (ROOT / "nfwserver").rglob("*.py")
               if "no rotor is configured" in path.read_text(encoding="utf-8")]
    assert holders == ["nfwserver/commands/actions.py"]


@pytest.mark.parametrize("word", ["TUNE", "SAT", "FLIP", "STATUS", "Z"])
def test_every_entry_holds_its_action(word) -> None:
    from nfwserver.commands.table import command

    assert callable(command(word).action)
