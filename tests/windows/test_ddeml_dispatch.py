"""The Windows transport's logic (DDEML callback -> handler), run on any OS with the real core."""

from __future__ import annotations

from nfwserver.clock import VirtualClock
from nfwserver.core.station_core import StationCore
from nfwserver.dde import ddeml
from nfwserver.dde.clipboard import CF_TEXT, CF_UNICODETEXT, encode_text
from nfwserver.dde.ddeml_dispatch import DdemlDispatcher
from nfwserver.dde.nova_service import NovaDdeService
from tests.dde.conftest import CATALOG, ISS, ISS_PASS, OBSERVER


class FakeApi:
    """Stands in for user32's string and data handles: integers mapping to Python values."""

    def __init__(self) -> None:
        self.strings: dict[int, str] = {}
        self.data: dict[int, bytes] = {}
        self.created: list[tuple[bytes, str, int]] = []

    def hsz(self, text: str) -> int:
        handle = 100 + len(self.strings)
        self.strings[handle] = text
        return handle

    def hdata(self, payload: bytes) -> int:
        handle = 5000 + len(self.data)
        self.data[handle] = payload
        return handle

    def query_string(self, hsz: int) -> str:
        return self.strings[hsz]

    def get_data(self, hdata: int) -> bytes:
        return self.data[hdata]

    def create_data(self, data: bytes, hsz_item: int, fmt: int) -> int:
        self.created.append((data, self.strings[hsz_item], fmt))
        return 9000 + len(self.created)


def _setup():
    core = StationCore(CATALOG, OBSERVER, VirtualClock(ISS_PASS.tca), satellite=ISS)
    server = NovaDdeService(core)
    api = FakeApi()
    handlers = {"NFW32": server, "NFW_SERVER": server}
    dispatch = DdemlDispatcher(lambda name: handlers.get(name.upper()), api)
    return server, api, dispatch


def _connect(api, dispatch, service="NFW32", topic="NFW_DATA", hconv=77) -> bool:
    topic_h, service_h = api.hsz(topic), api.hsz(service)
    ok = dispatch(ddeml.XTYP_CONNECT, 0, 0, topic_h, service_h, 0)
    if ok:
        dispatch(ddeml.XTYP_CONNECT_CONFIRM, 0, hconv, topic_h, service_h, 0)
    return bool(ok)


def test_connect_names_and_refusals() -> None:
    server, api, dispatch = _setup()
    assert _connect(api, dispatch, "nfw32", "nfw_data")
    assert not _connect(api, dispatch, "NFW32", "OTHER", hconv=78)
    assert not _connect(api, dispatch, "SOMEONE", "NFW_DATA", hconv=79)
    assert dispatch.conversation_count() == 1 and server.client_count()[0] == 1


def test_poke_request_advise_like_a_real_client() -> None:
    server, api, dispatch = _setup()
    assert _connect(api, dispatch)
    topic, item = api.hsz("NFW_DATA"), api.hsz("NFW_SERVER")
    ack = dispatch(ddeml.XTYP_POKE, CF_TEXT, 77, topic, item, api.hdata(encode_text("TUNE ON")))
    assert ack == ddeml.DDE_FACK
    refused = dispatch(ddeml.XTYP_POKE, CF_TEXT, 77, topic, item, api.hdata(b"JUNK\x00"))
    assert refused == ddeml.DDE_FNOTPROCESSED
    assert dispatch(ddeml.XTYP_ADVSTART, CF_TEXT, 77, topic, item, 0) == 1
    assert dispatch(ddeml.XTYP_ADVSTART, 49999, 77, topic, item, 0) == 0  # a format we do not serve
    server.core.tick()
    handle = dispatch(ddeml.XTYP_REQUEST, CF_TEXT, 77, topic, item, 0)
    assert handle and api.created[-1][0].startswith(b"ISS AZ:") and api.created[-1][0].endswith(b"\x00")
    assert api.created[-1][1] == "NFW_SERVER" and api.created[-1][2] == CF_TEXT
    dispatch(ddeml.XTYP_ADVREQ, CF_UNICODETEXT, 77, topic, item, 0)
    assert api.created[-1][0].decode("utf-16-le").startswith("ISS AZ:")
    assert dispatch(ddeml.XTYP_REQUEST, CF_TEXT, 77, topic, api.hsz("NOPE"), 0) == 0
    assert dispatch(ddeml.XTYP_EXECUTE, 0, 77, topic, 0, api.hdata(b"TRACK ON\x00")) == ddeml.DDE_FACK
    assert server.core.snapshot().state.tracking
    dispatch(ddeml.XTYP_ADVSTOP, CF_TEXT, 77, topic, item, 0)
    assert server.client_count()[1] == 0
    dispatch(ddeml.XTYP_DISCONNECT, 0, 77, 0, 0, 0)
    assert dispatch.conversation_count() == 0 and server.client_count()[0] == 0


def test_unknown_conversations_and_handler_failures_are_refused_not_raised() -> None:
    server, api, dispatch = _setup()
    topic, item = api.hsz("NFW_DATA"), api.hsz("NFW_SERVER")
    assert dispatch(ddeml.XTYP_POKE, CF_TEXT, 55, topic, item, api.hdata(b"TUNE ON\x00")) == ddeml.DDE_FNOTPROCESSED
    assert _connect(api, dispatch)
    # A data handle DDEML would not know: the API raises; the callback must still answer.
    assert dispatch(ddeml.XTYP_POKE, CF_TEXT, 77, topic, item, 424242) == ddeml.DDE_FNOTPROCESSED
    assert dispatch(ddeml.XTYP_REQUEST, CF_TEXT, 77, 999999, item, 0) == 0
    assert dispatch(ddeml.XTYP_WILDCONNECT, 0, 0, 0, 0, 0) == 0


def test_execute_arrives_whole_from_utf16_and_from_ansi_data() -> None:
    """A DdeInitializeW server gets executes as UTF-16; `TRACK ON` must not arrive as `T`."""
    server, api, dispatch = _setup()
    assert _connect(api, dispatch)
    topic = api.hsz("NFW_DATA")
    utf16 = "TRACK ON".encode("utf-16-le") + b"\x00\x00"
    assert dispatch(ddeml.XTYP_EXECUTE, 0, 77, topic, 0, api.hdata(utf16)) == ddeml.DDE_FACK
    assert server.core.snapshot().state.tracking
    assert dispatch(ddeml.XTYP_EXECUTE, 0, 77, topic, 0, api.hdata(b"TRACK OFF\x00")) == ddeml.DDE_FACK
    assert not server.core.snapshot().state.tracking
    assert dispatch(ddeml.XTYP_EXECUTE, 0, 77, topic, 0, api.hdata("BOGUS".encode("utf-16-le"))) \
        == ddeml.DDE_FNOTPROCESSED


def test_execute_command_conversion() -> None:
    from nfwserver.dde.ddeml_dispatch import execute_command

    assert execute_command("TUNE ON".encode("utf-16-le") + b"\x00\x00") == b"TUNE ON\x00"
    assert execute_command("TUNE ON".encode("utf-16-le")) == b"TUNE ON\x00"  # no terminator
    assert execute_command(b"TUNE ON\x00") == b"TUNE ON\x00"  # ANSI passed through
    assert execute_command(b"T\x00") in (b"T\x00",)  # one ANSI character reads the same either way
    assert execute_command("TUNE ON".encode("utf-16-le") + b"\x00\x00", unicode_instance=False) \
        == "TUNE ON".encode("utf-16-le") + b"\x00\x00"


def test_post_advise_stats_line_counts_links_like_ddeml_and_reads_back() -> None:
    """The station's stop line: every DdePostAdvise call, and the calls at the usual link count,
    whose link count is the dispatcher's (the links DDEML holds after ADVSTART/ADVSTOP/DISCONNECT)."""
    from nfwserver.dde.post_advise_stats import PostAdviseStats, parse_summary

    server, api, dispatch = _setup()
    topic, item = api.hsz("NFW_DATA"), api.hsz("nfw_server")
    for hconv in (77, 78, 79):
        assert _connect(api, dispatch, hconv=hconv)
        assert dispatch(ddeml.XTYP_ADVSTART, CF_TEXT, hconv, topic, item, 0) == 1
    dispatch(ddeml.XTYP_ADVSTART, CF_TEXT, 77, topic, item, 0)  # a restart keeps one link
    assert dispatch.advise_links("NFW_SERVER") == 3 and dispatch.advise_links("OTHER") == 0
    stats = PostAdviseStats()
    assert parse_summary(stats.summary()) == {"count": 0, "mean_ms": 0.0, "max_ms": 0.0}
    for seconds in (0.002, 0.004, 0.003):
        stats.add(seconds, dispatch.advise_links("NFW_SERVER"))
    dispatch(ddeml.XTYP_ADVSTOP, CF_TEXT, 78, topic, item, 0)
    dispatch(ddeml.XTYP_DISCONNECT, 0, 79, 0, 0, 0)
    assert dispatch.advise_links("NFW_SERVER") == 1
    stats.add(0.011, dispatch.advise_links("NFW_SERVER"))
    stats.add(0.001, dispatch.advise_links("NFW_DATA"))  # the station posts every item, linked or not
    stats.add(0.003, dispatch.advise_links("NFW_DATA"))
    line = stats.summary()
    assert line == ("DdePostAdvise: 6 calls, mean 4.000 ms, max 11.000 ms; "
                    "at 3 advise links (3 calls): mean 3.000 ms, max 4.000 ms; "
                    "at no link (2 calls): mean 2.000 ms, max 3.000 ms")
    log = f"INFO other\nINFO {PostAdviseStats().summary()}\nINFO {line}\nINFO stopped\n"
    assert parse_summary(log) == {"count": 6, "mean_ms": 4.0, "max_ms": 11.0, "links": 3, "steady_count": 3,
                                  "steady_mean_ms": 3.0, "steady_max_ms": 4.0, "idle_count": 2,
                                  "idle_mean_ms": 2.0, "idle_max_ms": 3.0}
    assert parse_summary("no such line") is None


def test_a_dropped_conversation_ends_its_links_and_gets_no_more_advise_data() -> None:
    """What the transport does for a client that vanished without disconnecting (windows_transport's
    _drop_vanished): the conversation ends for the station as by XTYP_DISCONNECT, and the XTYP_ADVREQ
    DDEML still sends for its stale link gets no data, so DDEML posts nothing to the dead window."""
    server, api, dispatch = _setup()
    assert _connect(api, dispatch, "NFW32", hconv=77) and _connect(api, dispatch, "NFW_SERVER", hconv=78)
    topic, item = api.hsz("NFW_DATA"), api.hsz("NFW_SERVER")
    for hconv in (77, 78):
        assert dispatch(ddeml.XTYP_ADVSTART, CF_TEXT, hconv, topic, item, 0) == 1
    server.core.tick()
    assert dispatch.advise_links("nfw_server") == 2 and server.client_count() == (2, 2)
    assert dispatch.describe(78) == "conversation 2 (NFW_SERVER/NFW_DATA)"
    assert sorted(dispatch.handles()) == [77, 78]
    dispatch.drop(78)
    assert dispatch.handles() == [77] and dispatch.advise_links("NFW_SERVER") == 1
    assert server.client_count() == (1, 1)
    assert dispatch(ddeml.XTYP_ADVREQ, CF_TEXT, 78, topic, item, 0) == 0
    assert dispatch(ddeml.XTYP_ADVREQ, CF_TEXT, 77, topic, item, 0) != 0
    assert dispatch.describe(78) == "conversation handle 0x4E"
    dispatch.drop(78)  # twice: nothing more happens
    assert server.client_count() == (1, 1)
