"""The server as real Nova clients use it, on the fake DDE transport and a virtual clock."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from nfwserver.commands.parsing import parse_request
from nfwserver.commands.table import Face
from nfwserver.core.events import Direction
from nfwserver.dde.clipboard import CF_TEXT, CF_UNICODETEXT
from nfwserver.fake_dde import DMLERR_NOTPROCESSED, DdeError
from tests.dde.conftest import ISS, NOVA, make_station


def test_wisp_style_polling_client_repokes_tune_on_until_data_flows(station) -> None:
    conv = station.system.connect("NFW32", "NFW_DATA", "WiSP")
    replies, pokes = [], []

    def client(offset: float) -> None:
        if round(offset * 5) % 15 == 0:  # every 3 s
            reply = conv.request_text("NFW_SERVER")
            replies.append(reply)
            if "AH:" not in reply:
                conv.poke("NFW_SERVER", "TUNE ON")
                pokes.append(offset)

    station.run(30.0, client)
    assert replies[0] == "" and pokes == [0.0]
    assert len(replies) == 11 and all(NOVA.match(r) for r in replies[1:])
    assert all(r.startswith("ISS ") for r in replies[1:])


def test_matlab_style_poke_then_request(station) -> None:
    conv = station.system.connect("NFW_SERVER", "NFW_DATA")
    conv.poke("NFW_SERVER", "TUNE ON")
    conv.poke("NFW_SERVER", "SAT=25544")
    station.core.tick()
    m = NOVA.match(conv.request_text("NFW_SERVER"))
    assert m and m.group(1) == "ISS"


def test_delphi_hot_advise_in_any_case_of_names(station) -> None:
    conv = station.system.connect("nfw32", "nfw_data")
    conv.start_advise("nfw_server", CF_TEXT, hot=True)
    conv.poke("Nfw_Server", "TUNE ON\x00")
    station.run(10.0)
    texts = conv.texts()
    assert len(texts) == 51  # 5 Hz for 10 s, both ends included
    assert all(NOVA.match(t) for t in texts)
    assert len({t for t in texts}) > 40  # the values move


def test_warm_link_notifies_and_the_client_requests(station) -> None:
    conv = station.system.connect("NFW32", "NFW_DATA")
    conv.start_advise("NFW_DATA", hot=False)
    conv.poke("NFW_DATA", "TUNE ON\r\n")
    station.run(2.0)
    kinds = [r.kind for r in conv.received]
    assert kinds == ["notify"] * 11
    assert NOVA.match(conv.request_text("NFW_DATA"))


def test_unicode_clients(station) -> None:
    conv = station.system.connect("NFW32", "NFW_DATA")
    conv.start_advise("NFW_SERVER", CF_UNICODETEXT)
    conv.poke("NFW_SERVER", "TUNE ON", CF_UNICODETEXT)
    station.run(1.0)
    assert conv.received[-1].data.endswith(b"\x00\x00")
    assert all(NOVA.match(t) for t in conv.texts())
    assert NOVA.match(conv.request("NFW_SERVER", CF_UNICODETEXT).decode("utf-16-le").rstrip("\x00"))


def test_nothing_before_tune_on_and_nothing_new_after_tune_off(station) -> None:
    conv = station.system.connect("NFW32", "NFW_DATA")
    conv.start_advise("NFW_SERVER")
    station.run(1.0)
    assert conv.texts() == [] and conv.request_text("NFW_SERVER") == ""
    conv.poke("NFW_SERVER", "TUNE ON")
    station.run(1.0)
    count = len(conv.texts())
    assert count == 6
    conv.poke("NFW_SERVER", "TUNE OFF")
    station.run(2.0)
    assert len(conv.texts()) == count and conv.request_text("NFW_SERVER") == ""


def test_unknown_satellite_keeps_the_current_one(station) -> None:
    conv = station.system.connect("NFW32", "NFW_DATA")
    conv.poke("NFW_SERVER", "TUNE ON")
    with pytest.raises(DdeError) as info:
        conv.poke("NFW_SERVER", "SAT=99999")
    assert info.value.code == DMLERR_NOTPROCESSED
    station.core.tick()
    assert conv.request_text("NFW_SERVER").startswith("ISS ")
    refusal = station.core.events.recent(direction=Direction.IN)[-1]
    assert refusal.accepted is False and "not in the catalog" in refusal.detail


def test_satellite_switch_renames_the_stream(station) -> None:
    other = next(s for s in station.core.catalog if s.catalog_number != ISS)
    conv = station.system.connect("NFW32", "NFW_DATA")
    conv.start_advise("NFW_SERVER")
    conv.poke("NFW_SERVER", "TUNE ON")
    station.run(1.0)
    conv.poke("NFW_SERVER", f"SAT={other.catalog_number}")
    station.run(1.0)
    names = [t.split()[0] for t in conv.texts()]
    assert names[0] == "ISS" and names[-1] == other.dde_name


def test_hundred_clients_at_ten_hertz_receive_the_same_stream() -> None:
    station = make_station(rate_hz=10.0)
    convs = [station.system.connect("NFW32", "NFW_DATA", f"c{k}") for k in range(100)]
    for conv in convs:
        conv.start_advise("NFW_SERVER")
    convs[0].poke("NFW_SERVER", "TUNE ON")
    station.run(10.0)
    first = convs[0].texts()
    assert len(first) == 101
    assert all(conv.texts() == first for conv in convs)
    assert station.nova.client_count()[1] == 100


def test_clients_disconnecting_mid_advise_do_not_disturb_the_rest(station) -> None:
    convs = [station.system.connect("NFW32", "NFW_DATA") for _ in range(10)]
    for conv in convs:
        conv.start_advise("NFW_SERVER")
    convs[0].poke("NFW_SERVER", "TUNE ON")

    def drop(offset: float) -> None:
        k = int(offset)
        if offset == k and 1 <= k <= 5:
            convs[k].disconnect()

    station.run(8.0, drop)
    for k, conv in enumerate(convs):
        expected = 41 if k == 0 or k > 5 else 5 * k
        assert len(conv.texts()) == expected, k
    assert station.nova.client_count()[0] == 5
    assert station.nova.client_count()[1] == 5


@settings(max_examples=150, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.one_of(st.text(max_size=80), st.binary(max_size=80)))
def test_fuzzed_pokes_never_disturb_another_conversation(junk) -> None:
    if isinstance(junk, str):
        assume(parse_request(junk, Face.DDE).error is not None)  # a valid command may change the session
    station = make_station()
    victim = station.system.connect("NFW32", "NFW_DATA")
    victim.start_advise("NFW_SERVER")
    victim.poke("NFW_SERVER", "TUNE ON")
    attacker = station.system.connect("NFW32", "NFW_DATA")
    station.run(0.4)
    before = station.core.snapshot()
    try:
        attacker.poke("NFW_SERVER", junk)
    except DdeError as exc:
        assert exc.code == DMLERR_NOTPROCESSED
    else:  # binary data can decode to a valid command; then it must have been one
        assert isinstance(junk, bytes)
    station.run(0.4)
    after = station.core.snapshot()
    if isinstance(junk, str):
        assert (after.state.feed_on, after.catalog_number) == (before.state.feed_on, before.catalog_number)
    assert len(victim.texts()) >= 3 or not after.state.feed_on


def test_tick_listeners_and_a_broken_listener(station) -> None:
    samples = []
    station.core.subscribe(lambda s: 1 / 0)
    remove = station.core.subscribe(samples.append)
    station.core.command("TUNE ON")
    station.run(1.0)
    assert len(samples) == 6 and samples[-1].catalog_number == ISS and samples[-1].text
    remove()
    station.run(1.0)
    assert len(samples) == 6


def test_event_stream_shows_incoming_and_outgoing(station) -> None:
    conv = station.system.connect("NFW32", "NFW_DATA")
    conv.poke("NFW_SERVER", "TUNE ON")
    conv.poke("NFW_SERVER", "ANTAZ=123.4")
    conv.poke("NFW_SERVER", "ANTEL=45.6")
    station.run(0.4)
    incoming = [e for e in station.core.events.recent(direction=Direction.IN) if e.kind == "poke"]
    assert [e.text for e in incoming] == ["TUNE ON", "ANTAZ=123.4", "ANTEL=45.6"]
    assert all(e.conversation == conv.conv_id and e.accepted for e in incoming)
    outgoing = station.core.events.recent(direction=Direction.OUT)
    assert len(outgoing) == 3 and NOVA.match(outgoing[-1].text)
    antenna = station.core.snapshot().state.antenna
    assert (antenna.azimuth_deg, antenna.elevation_deg) == (123.4, 45.6)


def test_rate_limits() -> None:
    with pytest.raises(ValueError):
        make_station(rate_hz=0.5)
    with pytest.raises(ValueError):
        make_station(rate_hz=51)
