"""Every face parses through the one command table (issue 24): what TCP answers, what the help says,
and that docs/COMMANDS.md is the table's current text."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from nfwserver.commands.help_text import help_lines, markdown, poke_epilog
from nfwserver.commands.table import COMMANDS, Face
from tests.dde.conftest import CATALOG
from tests.tcp.conftest import LineClient
from tests.waiting import wait_for

ROOT = Path(__file__).resolve().parents[2]


def test_docs_commands_is_generated_from_the_table() -> None:
    committed = (ROOT / "docs" / "COMMANDS.md").read_text(encoding="utf-8")
    assert committed == markdown(), "docs/COMMANDS.md is stale: python -m nfwserver.commands > docs/COMMANDS.md"
    printed = subprocess.run([sys.executable, "-m", "nfwserver.commands"], cwd=ROOT, capture_output=True,
                             text=True, check=True).stdout
    assert printed == committed


def test_every_command_is_in_the_document_and_on_the_faces_its_entry_names() -> None:
    doc = markdown()
    for entry in COMMANDS:
        assert f"`{entry.usage.replace('|', chr(92) + '|')}`" in doc
        for face in (Face.TCP, Face.CONSOLE):
            listed = any(line.startswith(entry.usage + " ") for line in help_lines(face))
            assert listed == bool(entry.faces & face), (entry.word, face)


def test_help_over_tcp_is_one_line_per_command_then_ok(tcp_station, client) -> None:
    client.send(b"help\r\n")
    lines = [client.text() for _ in range(len(help_lines(Face.TCP)) + 1)]
    assert lines[-1] == "OK"
    words = [line.split()[0].split("=")[0] for line in lines[:-1]]
    assert words == ["TUNE", "TRACK", "SAT", "ANTAZ", "ANTEL", "DOPPLER", "AUTO", "SUMMARY", "STATUS", "WATCH",
                     "HELP", "QUIT", "FLIP", "PARK"]


def test_poke_help_lists_the_tcp_commands() -> None:
    out = subprocess.run([sys.executable, "-m", "nfwserver", "poke", "--help"], cwd=ROOT, capture_output=True,
                         text=True, check=True).stdout
    for line in help_lines(Face.TCP):
        assert line.split()[0] in out
    assert poke_epilog().splitlines()[0] in out


def test_flip_without_a_rotor_says_so_before_judging_the_argument(tcp_station, client) -> None:
    assert client.ask("FLIP") == "ERROR no rotor is configured"
    assert client.ask("FLIP sideways") == "ERROR no rotor is configured"


def test_flip_with_a_rotor_checks_the_argument(tcp_station, client) -> None:
    _, server = tcp_station
    modes: list[str] = []

    class Rotor:
        def set_flip_mode(self, mode: str) -> None:
            modes.append(mode)

        def request_park(self) -> None:
            modes.append("park")

    server.core.rotor = Rotor()
    assert client.ask("FLIP sideways") == "ERROR FLIP needs AUTO, ON or OFF"
    assert client.ask("flip On") == "OK"
    assert modes == ["on"]


def test_track_on_without_a_rotor_is_a_warning_not_a_bare_ok(tcp_station, client) -> None:
    station, _ = tcp_station
    station.core.rotor_configured = False
    reply = client.ask("TRACK ON")
    assert reply.startswith("OK warning: ") and "no rotor" in reply
    assert station.core.state.snapshot().tracking
    station.core.rotor_configured = True
    assert client.ask("TRACK ON") == "OK"


@pytest.mark.parametrize(("name", "expected"), [("oao 2", 3597), ("ISIS-1", 3669)])
def test_sat_by_a_unique_name_over_tcp(tcp_station, client, name: str, expected: int) -> None:
    station, _ = tcp_station
    assert client.ask(f"SAT={name}") == "OK"
    assert station.core.state.catalog_number == expected


def test_sat_by_an_ambiguous_or_unknown_name_is_refused_and_changes_nothing(tcp_station, client) -> None:
    station, _ = tcp_station
    before = station.core.state.catalog_number
    named = sorted(s.catalog_number for s in CATALOG if s.name == "SL-8 R/B")
    assert len(named) > 5
    reply = client.ask("SAT=sl-8 r/b")
    assert reply == (f"ERROR {len(named)} satellites are named 'sl-8 r/b' ({', '.join(map(str, named[:5]))}, ...); "
                     "use the catalog number; keeping the current one")
    assert client.ask("SAT=NO SUCH BIRD").startswith("ERROR no satellite is named 'NO SUCH BIRD'")
    assert station.core.state.catalog_number == before


def test_a_dde_poke_takes_catalog_numbers_only(tcp_station) -> None:
    station, _ = tcp_station
    assert not station.core.command("SAT=OAO 2", source="dde").accepted


def test_the_line_that_ends_watch_is_not_executed(tcp_station, client) -> None:
    station, server = tcp_station
    station.core.set_feed(True)
    assert client.ask("WATCH") == "OK"
    assert wait_for(lambda: server.watcher_count() == 1)
    client.send(b"TUNE OFF\r\n")
    assert wait_for(lambda: server.watcher_count() == 0)
    while (line := client.text()) != "OK":
        assert line.startswith("ISS ")  # strings published before the stop line
    assert station.core.state.snapshot().feed_on  # TUNE OFF ended the stream; it was not executed
    assert client.ask("STATUS").startswith("satellite=")


def test_an_unknown_line_lists_the_station_commands(tcp_station, client) -> None:
    assert client.ask("HELLO") == ("ERROR not a Nova command (TUNE ON|OFF, TRACK ON|OFF, SAT=n, ANTAZ=deg, "
                                   "ANTEL=deg, DOPPLER ON|OFF, AUTO ON|OFF)")


def test_a_line_client_reads_replies(tcp_station) -> None:
    _, server = tcp_station
    c = LineClient(server.address)
    try:
        c.read_line()
        assert c.ask("QUIT") == "OK"
    finally:
        c.close()
