"""The one STATUS codec (issue 36 item 2): the station writes the line with it, every reader reads it with it."""

from __future__ import annotations

import re

from nfwserver.tcp.status_line import format_status, parse_status

#: The protocol's words: key=value pairs separated by single blanks; a value is a word with no blank or control
#: character, or prose in double quotes (``\"`` and ``\\`` escaped inside), never with a control character.
_VALUE = r'(?:"(?:[^"\\\x00-\x1f\x7f]|\\["\\])*"|[^\s"]\S*)'
WELL_FORMED = re.compile(rf"[^\s=]+={_VALUE}( [^\s=]+={_VALUE})*")


def test_the_line_is_written_as_the_protocol_says() -> None:
    line = format_status({"satellite": 25544, "name": None, "tune": True, "track": False,
                          "rotor_fault": "lost link\tto rotctld", "empty": ""})
    assert line == 'satellite=25544 name=- tune=on track=off rotor_fault="lost link to rotctld" empty=-'


def test_reading_gives_back_the_pairs_in_order() -> None:
    line = "satellite=25544 name=ISS faults=none note=a=b"
    assert list(parse_status(line).items()) == [("satellite", "25544"), ("name", "ISS"), ("faults", "none"),
                                                ("note", "a=b")]
    assert format_status(parse_status(line)) == line


def test_a_running_station_sends_a_well_formed_line(tcp_station, client) -> None:
    station, server = tcp_station
    server.protocol.extra = lambda: {"rotor": "ok", "note": "two words\r\nand a line"}
    station.run(0.4)
    line = client.ask("STATUS")
    assert WELL_FORMED.fullmatch(line), line
    fields = parse_status(line)
    assert format_status(fields) == line and fields["note"] == "two words and a line"


def test_prose_reads_back_as_written_quotes_and_backslashes_included() -> None:
    reason = 'rigctld: "busy" at C:\\COM3 (2 failures)'
    line = format_status({"radio_fault": reason, "faults": "radio"})
    assert line == 'radio_fault="rigctld: \\"busy\\" at C:\\\\COM3 (2 failures)" faults=radio'
    assert parse_status(line) == {"radio_fault": reason, "faults": "radio"}
