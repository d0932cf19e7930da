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
    ("BOGUS", "ERROR not a Nova command (TUNE ON|OFF, TRACK ON|OFF, SAT=n, ANTAZ=deg, ANTEL=deg, "
              "DOPPLER ON|OFF, AUTO ON|OFF)"),
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


def test_the_console_keys_act_through_their_table_entries_without_text(monkeypatch) -> None:
    """Ctrl+T, Ctrl+D, Ctrl+F, F4 and F2's picker hand the core their table entry and argument as the console's:
    no grammar is tried (before, the keys built ``TUNE``/``FLIP``/``SAT=`` text to parse again, F4 and z toggled
    the zone behind the ``Z`` entry, and Ctrl+D had no entry at all); every one is recorded by the core."""
    station = make_station()
    core = station.core
    sent: list[tuple[str, object, Face]] = []
    tried: list[str] = []
    execute, match = core.execute, Command.match

    def record_execute(request: Request, *args, **kwargs):
        sent.extend((p.command.word, p.value, request.face) for p in request.commands)
        return execute(request, *args, **kwargs)

    def counting(self: Command, text: str):
        tried.append(text)
        return match(self, text)

    monkeypatch.setattr(core, "execute", record_execute)
    monkeypatch.setattr(Command, "match", counting)

    async def scenario() -> None:
        app = NfwConsole(core)
        async with app.run_test(size=(120, 40)) as pilot:
            await settle(app, pilot, until=lambda: searched(app), what="the first pass search")
            for key in ("ctrl+t", "ctrl+d", "ctrl+f", "f4"):
                await pilot.press(key)
            app._picked(3597)
            await settle(app, pilot, until=lambda: len(sent) >= 5)

    asyncio.run(scenario())
    assert sent == [("TUNE", True, Face.CONSOLE), ("DOPPLER", True, Face.CONSOLE), ("FLIP", "auto", Face.CONSOLE),
                    ("Z", None, Face.CONSOLE), ("SAT", 3597, Face.CONSOLE)]
    assert tried == []
    assert core.state.feed_on and core.state.doppler_on and core.state.catalog_number == 3597
    recorded = [(e.text, e.accepted) for e in core.events.recent() if e.client == "console" and e.kind != "note"]
    assert recorded == [("TUNE ON", True), ("DOPPLER ON", True), ("FLIP AUTO", False), ("Z", True), ("SAT=3597", True)]


def test_the_no_rotor_reason_is_written_once() -> None:
    """Every face says why a rotor command is refused in the words of one constant."""
    holders = [path.relative_to(ROOT).as_posix() for path in (ROOT / "nfwserver").rglob("*.py")
               if "no rotor is configured" in path.read_text(encoding="utf-8")]
    assert holders == ["nfwserver/commands/actions.py"]


@pytest.mark.parametrize("word", ["TUNE", "SAT", "FLIP", "STATUS", "Z"])
def test_every_entry_holds_its_action(word) -> None:
    from nfwserver.commands.table import command

    assert callable(command(word).action)
