"""Nova's TCP server over real sockets on 127.0.0.1: greeting, SUMMARY, commands, STATUS, WATCH, refusals."""

from __future__ import annotations

import pytest

from nfwserver.config.schema import TcpConfig
from nfwserver.core.events import Direction
from nfwserver.tcp.server import NovaTcpServer
from nfwserver.tcp.status_line import parse_status
from tests.dde.conftest import CATALOG, make_station
from tests.tcp.conftest import LOOPBACK_ONLY, LineClient
from tests.waiting import wait_for

SO_50 = 27607  # not in visual.txt: a catalog number the station does not know
OTHER = 694  # ATLAS-CENT-2, in visual.txt


def test_greeting_is_byte_exact(tcp_station) -> None:
    _, server = tcp_station
    c = LineClient(server.address)
    try:
        assert c.read_line() == b"Hello, this is Nova for Windows.\r\n"
        assert server.client_count() == 1
    finally:
        c.close()
    assert wait_for(lambda: server.client_count() == 0)


def test_summary_is_the_dde_string_of_the_same_tick(tcp_station, client) -> None:
    station, _ = tcp_station
    conv = station.system.connect("NFW32", "NFW_DATA")
    assert client.ask("SUMMARY") == ""  # before TUNE ON: an empty line, as DDE's empty string
    conv.poke("NFW_SERVER", "TUNE ON")
    for _ in range(5):
        station.run(1.0)
        dde = conv.request_text("NFW_SERVER")
        assert dde.startswith("ISS AZ:") and " AH:" in dde
        assert client.ask("SUMMARY") == dde


def test_commands_change_what_dde_clients_see(tcp_station, client) -> None:
    station, _ = tcp_station
    conv = station.system.connect("NFW32", "NFW_DATA")
    assert client.ask("TUNE ON") == "OK"
    station.run(0.2)
    assert conv.request_text("NFW_SERVER").startswith("ISS AZ:")
    assert client.ask(f"SAT={OTHER}") == "OK"
    station.run(0.2)
    assert conv.request_text("NFW_SERVER").startswith(f"{CATALOG.get(OTHER).dde_name} AZ:")
    assert client.ask(f"sat = {SO_50}") == f"ERROR satellite {SO_50} is not in the catalog; keeping the current one"
    assert client.ask("ANTAZ=123.5") == "OK" and client.ask("ANTEL=45") == "OK"
    antenna = station.core.state.snapshot().antenna
    assert (antenna.azimuth_deg, antenna.elevation_deg) == (123.5, 45.0)
    assert client.ask("TRACK ON") == "OK" and station.core.state.snapshot().tracking
    assert client.ask("TUNE OFF") == "OK"
    station.run(0.2)
    assert conv.request_text("NFW_SERVER") == ""
    assert client.ask("TRACK OFF") == "OK" and not station.core.state.snapshot().tracking


def test_an_ignored_track_on_and_unknown_lines_answer_error() -> None:
    station = make_station(satellite=None)
    server = NovaTcpServer(station.core, LOOPBACK_ONLY)
    server.start()
    c = LineClient(server.address)
    try:
        c.read_line()
        assert c.ask("TRACK ON") == "ERROR TRACK ON ignored: no satellite elements set"
        assert not station.core.state.snapshot().tracking
        assert c.ask("HELLO\tWORLD").startswith("ERROR not a Nova command")
        assert c.ask("TUNE SIDEWAYS") == "ERROR TUNE needs ON or OFF"
    finally:
        c.close()
        server.stop()


def test_commands_reach_the_event_stream_with_the_peer_address(tcp_station, client) -> None:
    station, _ = tcp_station
    port = client.sock.getsockname()[1]
    client.ask("TUNE ON")
    client.ask("SUMMARY")
    peer = f"tcp 127.0.0.1:{port}"
    incoming = [e for e in station.core.events.recent(direction=Direction.IN) if e.client == peer]
    assert [(e.kind, e.text) for e in incoming] == [("connect", "TCP"), ("poke", "TUNE ON"), ("request", "SUMMARY")]
    assert incoming[1].accepted is True


def test_every_line_end_is_understood_and_replies_end_with_crlf(tcp_station, client) -> None:
    station, _ = tcp_station
    station.core.set_feed(True)
    station.run(0.2)
    expected = station.core.current_text().encode() + b"\r\n"
    client.send(b"SUMMARY\rSUMMARY\nSUMMARY\r\nSUMMARY\x00summary \r")
    assert [client.read_line() for _ in range(5)] == [expected] * 5
    client.send(b"SUMM")  # a line may arrive in pieces, and CR LF may be split between reads
    client.send(b"ARY\r")
    assert client.read_line() == expected
    client.send(b"\nSTATUS\r\n")  # the LF belongs to the CR before it: no empty line, no reply for it
    assert client.text().startswith("satellite=25544 ")


def test_status_is_one_line_of_key_values(tcp_station, client) -> None:
    station, server = tcp_station
    server.protocol.extra = lambda: {"rotor": "ok", "rotor_az": "12.5", "note": "two words"}
    station.core.set_feed(True)
    station.run(0.4)
    fields = parse_status(client.ask("STATUS"))
    sample = station.core.tracker.last_sample
    assert fields["satellite"] == "25544" and fields["name"] == "ISS"
    assert (fields["tune"], fields["track"], fields["radio_tuning"]) == ("on", "off", "off")
    assert fields["status"] == f"0x{station.core.tracker.status_word():04X}"
    assert fields["interface"] == "1"
    assert f"AZ:{fields['az']} EL:{fields['el']} RR:{fields['rr']} AH:{fields['ah']}" in sample.text
    assert (fields["rotor"], fields["rotor_az"], fields["note"]) == ("ok", "12.5", "two words")


def test_watch_streams_every_published_string_until_a_line_arrives(tcp_station, client) -> None:
    station, server = tcp_station
    station.core.set_feed(True)
    published: list[str] = []
    station.core.subscribe(lambda s: published.append(s.text))
    assert client.ask("WATCH") == "OK"
    assert wait_for(lambda: server.watcher_count() == 1)
    station.run(2.0)  # 11 ticks at 5 Hz
    assert [client.text() for _ in published] == published and len(published) == 11
    client.send(b"\r\n")  # any line, even an empty one, ends WATCH: answered OK, not executed
    assert client.text() == "OK"
    assert wait_for(lambda: server.watcher_count() == 0)
    station.run(1.0)
    assert client.ask("QUIT") == "OK"
    assert client.read_line() == b""  # closed after QUIT


def test_a_line_longer_than_1_kib_is_refused_and_the_rest_of_it_discarded(tcp_station, client) -> None:
    _, server = tcp_station
    client.send(b"X" * 1024 + b"\r\n")  # exactly 1 KiB: reaches the command parser (which refuses it)
    assert client.text() == "ERROR poke of 1024 characters is too long"
    client.send(b"TUNE ON" + b"Y" * 5000)  # not terminated yet: refused as soon as it passes 1 KiB
    assert client.text() == "ERROR line longer than 1024 bytes refused"
    client.send(b"Z" * 100_000 + b"\nSUMMARY\n")  # the rest of that line is thrown away
    assert client.text() == ""  # SUMMARY before TUNE ON: an empty line; nothing else was answered
    assert server.stats.max_buffered < 2048


def test_a_peer_not_in_allow_is_closed_at_once(tcp_station, caplog) -> None:
    station, server = tcp_station
    foreign = LineClient(server.address, bind="127.0.0.2")
    try:
        try:
            assert foreign.read_line() == b""  # no greeting: closed
        except ConnectionResetError:
            pass
    finally:
        foreign.close()
    assert wait_for(lambda: server.stats.refused == 1)
    assert server.client_count() == 0
    assert "TCP connection from tcp 127.0.0.2:" in caplog.text and "not in [tcp] allow" in caplog.text
    notes = [e for e in station.core.events.recent() if e.client.startswith("tcp 127.0.0.2:")]
    assert notes and notes[0].accepted is False
    ok = LineClient(server.address)  # loopback itself is still welcome
    try:
        assert ok.read_line() == b"Hello, this is Nova for Windows.\r\n"
    finally:
        ok.close()


def test_allow_accepts_networks() -> None:
    station = make_station()
    server = NovaTcpServer(station.core, TcpConfig(enabled=True, host="127.0.0.1", port=0, allow=("127.0.0.0/8",)))
    server.start()
    c = LineClient(server.address, bind="127.0.0.2")
    try:
        assert c.read_line() == b"Hello, this is Nova for Windows.\r\n"
    finally:
        c.close()
        server.stop()


def test_binding_a_busy_port_raises_and_construction_binds_nothing(tcp_station) -> None:
    station, server = tcp_station
    busy = TcpConfig(enabled=True, host="127.0.0.1", port=server.address[1], allow=("127.0.0.1/32",))
    second = NovaTcpServer(station.core, busy)
    assert second.address is None
    with pytest.raises(OSError):
        second.start()


def test_stop_closes_every_client(tcp_station) -> None:
    _, server = tcp_station
    clients = [LineClient(server.address) for _ in range(3)]
    for c in clients:
        c.read_line()
    assert wait_for(lambda: server.client_count() == 3)
    server.stop()
    for c in clients:
        try:
            assert c.read_line() == b""
        except (TimeoutError, ConnectionResetError):
            pytest.fail("the server did not close the connection")
        c.close()


def test_flip_sets_the_rotors_inverted_tracking_mode(tcp_station, client) -> None:
    # FlipAnts: function 7F forces inverted tracking on, 7E off; "auto" chooses per pass.
    from nfwserver.rotor.geometry import RotorGeometry
    from tests.dde.conftest import ISS_PASS
    from tests.rotor.conftest import rotor_station

    assert client.ask("FLIP ON") == "ERROR no rotor is configured"  # this station has no rotor
    clock, core, _, _, coupling, _ = rotor_station(ISS_PASS.aos, RotorGeometry.preset("north-stop+flip"))
    core.rotor = coupling  # as the station sets it
    server = NovaTcpServer(core, LOOPBACK_ONLY)
    server.start()
    try:
        with_rotor = LineClient(server.address)
        with_rotor.read_line()
        for command, mode in (("flip on", "on"), ("FLIP OFF", "off"), ("FLIP auto", "auto")):
            assert with_rotor.ask(command) == "OK" and coupling.flip_mode == mode
        assert with_rotor.ask("FLIP SIDEWAYS") == "ERROR FLIP needs AUTO, ON or OFF"
        assert coupling.flip_mode == "auto"
        with_rotor.close()
    finally:
        server.stop()


def test_status_names_every_failing_link_while_its_fault_lasts(tcp_station, client) -> None:
    station, _ = tcp_station
    fields = parse_status(client.ask("STATUS"))
    assert fields["faults"] == "none"
    link = station.core.health.link("radio")
    link.failed("rigctld: connection refused")
    fields = parse_status(client.ask("STATUS"))
    assert fields["faults"] == "radio"
    assert fields["radio_fault"].startswith("rigctld: connection refused (1 failure in ")
    link.succeeded()
    fields = parse_status(client.ask("STATUS"))
    assert fields["faults"] == "none" and "radio_fault" not in fields
