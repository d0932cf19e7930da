"""The fake DDEML keeps DDEML's rules (DESIGN.md §4)."""

from __future__ import annotations

import pytest

from nfwserver.dde.clipboard import CF_UNICODETEXT, decode_text, encode_text
from nfwserver.dde.transport import PokeResult
from nfwserver.fake_dde import (
    DMLERR_BUSY,
    DMLERR_INVALIDPARAMETER,
    DMLERR_NO_CONV_ESTABLISHED,
    DMLERR_NOTPROCESSED,
    DMLERR_SERVER_DIED,
    DdeError,
    FakeDdeSystem,
)


class EchoServer:
    """A minimal server: topic T, item VALUE holds the last poked text; item BOOM raises."""

    def __init__(self) -> None:
        self.value = "initial"
        self.calls: list[str] = []
        self.busy = False

    def on_connect(self, service, topic):
        return topic.upper() == "T"

    def on_connect_confirm(self, conv, service, topic):
        self.calls.append(f"confirm {conv}")

    def on_request(self, conv, topic, item, fmt):
        if item.upper() == "BOOM":
            raise RuntimeError("handler bug")
        return encode_text(self.value, fmt) if item.upper() == "VALUE" else None

    def on_poke(self, conv, topic, item, fmt, data):
        if self.busy:
            return PokeResult.FBUSY
        if item.upper() == "BOOM":
            raise RuntimeError("handler bug")
        self.value = decode_text(data, fmt)
        return PokeResult.FACK

    def on_execute(self, conv, topic, command):
        return PokeResult.FACK if command.startswith(b"[ok]") else PokeResult.FNOTPROCESSED

    def on_advise_start(self, conv, topic, item, fmt):
        self.calls.append(f"advstart {conv} {item}")
        return item.upper() == "VALUE"

    def on_advise_request(self, conv, topic, item, fmt):
        return encode_text(self.value, fmt)

    def on_advise_stop(self, conv, topic, item, fmt):
        self.calls.append(f"advstop {conv} {item}")

    def on_disconnect(self, conv):
        self.calls.append(f"disconnect {conv}")


@pytest.fixture
def world():
    system = FakeDdeSystem()
    server = EchoServer()
    transport = system.server_transport()
    transport.register_service("Echo", server)
    return system, server, transport


def test_connect_is_case_insensitive_and_refusals_are_dmlerr(world) -> None:
    system, _, _ = world
    assert system.connect("ECHO", "t").connected
    with pytest.raises(DdeError) as info:
        system.connect("nobody", "T")
    assert info.value.code == DMLERR_NO_CONV_ESTABLISHED
    with pytest.raises(DdeError) as info:
        system.connect("echo", "other topic")
    assert info.value.code == DMLERR_NO_CONV_ESTABLISHED
    with pytest.raises(DdeError) as info:
        system.connect("x" * 256, "T")
    assert info.value.code == DMLERR_INVALIDPARAMETER


def test_request_poke_execute(world) -> None:
    system, server, _ = world
    conv = system.connect("echo", "T")
    conv.poke("value", "hello")
    assert conv.request_text("VALUE") == "hello"
    assert conv.request("Value") == b"hello\x00"
    assert conv.request("VALUE", CF_UNICODETEXT) == "hello".encode("utf-16-le") + b"\x00\x00"
    conv.poke("VALUE", "wide", CF_UNICODETEXT)
    assert server.value == "wide"
    with pytest.raises(DdeError) as info:
        conv.request("unknown")
    assert info.value.code == DMLERR_NOTPROCESSED
    conv.execute("[ok] go")
    with pytest.raises(DdeError) as info:
        conv.execute("[no]")
    assert info.value.code == DMLERR_NOTPROCESSED
    server.busy = True
    with pytest.raises(DdeError) as info:
        conv.poke("VALUE", "x")
    assert info.value.code == DMLERR_BUSY
    assert [r.kind for r in conv.received] == ["reply", "reply", "reply"]


def test_hot_and_warm_links_and_second_advstart_changes_the_link(world) -> None:
    system, server, transport = world
    hot = system.connect("Echo", "T")
    warm = system.connect("Echo", "T")
    hot.start_advise("VALUE")
    warm.start_advise("value", hot=False)
    server.value = "one"
    transport.post_advise("t", "VALUE")
    assert hot.texts() == ["one"]
    assert [r.kind for r in warm.received] == ["notify"] and warm.received[0].data is None
    assert warm.request_text("VALUE") == "one"
    warm.start_advise("VALUE", hot=True)  # same loop: now hot, not a second loop
    server.value = "two"
    transport.post_advise("T", "value")
    assert warm.texts() == ["two"]
    assert system.advise_loop_count() == 2
    assert sum(c.startswith("advstart") for c in server.calls) == 2
    with pytest.raises(DdeError):
        hot.start_advise("NOT_AN_ITEM")
    hot.stop_advise("VALUE")
    transport.post_advise("T", "VALUE")
    assert hot.texts() == ["one", "two"]
    with pytest.raises(DdeError):
        hot.stop_advise("VALUE")


def test_raising_callback_breaks_only_its_transaction(world) -> None:
    system, server, transport = world
    a = system.connect("Echo", "T")
    b = system.connect("Echo", "T")
    b.start_advise("VALUE")
    with pytest.raises(DdeError) as info:
        a.request("BOOM")
    assert info.value.code == DMLERR_NOTPROCESSED
    with pytest.raises(DdeError):
        a.poke("BOOM", "x")
    server.value = "still fine"
    transport.post_advise("T", "VALUE")
    assert b.texts() == ["still fine"]
    assert a.request_text("VALUE") == "still fine"


def test_disconnect_and_server_shutdown(world) -> None:
    system, server, transport = world
    a = system.connect("Echo", "T")
    a.start_advise("VALUE")
    a.disconnect()
    a.disconnect()
    assert f"disconnect {a.conv_id}" in server.calls
    with pytest.raises(DdeError) as info:
        a.request("VALUE")
    assert info.value.code == DMLERR_SERVER_DIED
    b = system.connect("Echo", "T")
    transport.close()
    assert not b.connected and b.received[-1].kind == "disconnect"
    with pytest.raises(DdeError):
        system.connect("Echo", "T")
    assert system.conversation_count() == 0


def test_client_sees_everything_in_order(world) -> None:
    system, server, transport = world
    conv = system.connect("Echo", "T")
    conv.start_advise("VALUE")
    seen = []
    conv.on_receive = lambda r: seen.append(r.seq)
    for k in range(5):
        server.value = str(k)
        transport.post_advise("T", "VALUE")
        conv.request("VALUE")
    assert conv.texts(("data", "reply")) == [str(k) for k in range(5) for _ in range(2)]
    assert seen == sorted(seen) and len(seen) == 10
