"""Real DDEML clients behaving like the public programs that read Nova's feed (DESIGN.md 5b), against
``nfwserver run --headless`` in another process (the ``station`` fixture: ISS, 10 Hz).

Runs where DDEML exists: under Wine via ``tools/wine/test`` (CI), or on Windows.
"""

from __future__ import annotations

import sys
import time

import pytest

from tests.windows.conftest import NOVA, on_linked_item, request_after_refusal, wine_version

pytestmark = [
    pytest.mark.windows,
    pytest.mark.skipif(sys.platform != "win32", reason="needs Windows DDEML"),
]


@pytest.fixture
def client():
    from nfwserver.dde.ddeml_client import DdemlClient

    made = []

    def make(**kwargs):
        made.append(DdemlClient(**kwargs))
        return made[-1]

    yield make
    for c in made:
        c.close()


def test_wisp_dde_client_polls_by_request_and_repokes_when_ah_is_missing(station, client) -> None:
    """VB6 (ANSI): poke TUNE ON, then plain requests; a reply without AH: makes it poke again."""
    wisp = client(ansi=True)
    conv = wisp.connect("NFW32", "NFW_DATA")
    wisp.poke(conv, "NFW_SERVER", "TUNE ON")
    replies = []
    for _ in range(6):  # the poll interval shortened from 3 s to 0.25 s
        wisp.pump(0.25)
        text = wisp.request_text(conv, "NFW_SERVER")  # never refused: the poll has no error handler
        if "AH:" not in text:
            wisp.poke(conv, "NFW_SERVER", "TUNE ON")
        replies.append(text)
    good = [r for r in replies if r]
    assert len(good) >= 4 and all(NOVA.match(r) for r in good)
    assert {r.split(" ")[0] for r in good} == {"ISS"}  # the first word is the name


def test_wisp_interval_zero_holds_a_warm_link_and_requests_per_notification(station, client) -> None:
    wisp = client(ansi=True)
    conv = wisp.connect("NFW32", "NFW_DATA")
    wisp.poke(conv, "NFW_SERVER", "TUNE ON")
    wisp.start_advise(conv, "NFW_SERVER", hot=False)
    texts = []
    for _ in range(5):
        seen = len(wisp.received)
        assert wisp.pump(2.0, until=lambda seen=seen: len(wisp.received) > seen)
        assert wisp.received[-1][1] is None  # warm: a notification without data
        texts.append(on_linked_item(wisp, lambda: wisp.request_text(conv, "NFW_SERVER")))
    assert all(NOVA.match(t) for t in texts[1:])


def test_delphi_tddeclientconv_warm_link_requests_and_poke_with_nul(station, client) -> None:
    delphi = client(ansi=True)
    conv = delphi.connect("NFW_SERVER", "NFW_DATA")
    delphi.start_advise(conv, "NFW_SERVER", hot=False, timeout_ms=1000)  # ADVSTART|XTYPF_NODATA, 1000 ms
    first = on_linked_item(delphi, lambda: delphi.request(conv, "NFW_SERVER"))  # the immediate request
    assert first.split(b"\x00")[0] in (b"",) or NOVA.match(first.split(b"\x00")[0].decode("cp1252"))
    on_linked_item(delphi, lambda: delphi.poke(conv, "NFW_SERVER", b"TUNE ON\x00"))  # PokeData: text + NUL
    strings = []
    for _ in range(4):
        seen = len(delphi.received)
        assert delphi.pump(2.0, until=lambda seen=seen: len(delphi.received) > seen)
        reply = on_linked_item(delphi, lambda: delphi.request(conv, "NFW_SERVER"))
        strings.append(reply.split(b"\x00")[0].decode("cp1252"))  # cut at NUL
    assert all(NOVA.match(s) for s in strings[1:])


def test_ndde_hot_link_and_request_polling_on_one_conversation(station, client) -> None:
    """.NET NDde: hot advise loop and a request every second on the same conversation."""
    ndde = client()
    conv = ndde.connect("NFW32", "NFW_DATA")
    ndde.poke(conv, "NFW_SERVER", "TUNE ON")
    ndde.start_advise(conv, "NFW_SERVER", hot=True)
    polled = []
    for _ in range(3):
        ndde.pump(1.0)
        polled.append(ndde.request_text(conv, "NFW_SERVER"))
    hot = [d for _, d in ndde.received if d]
    assert len(hot) >= 25  # 10 Hz for 3 s, minus start-up
    assert all(NOVA.match(d.split(b"\x00")[0].decode("cp1252")) for d in hot)
    # Under Wine a request may be answered with advise data; it is still a whole Nova string.
    assert all(NOVA.match(p) for p in polled)


def test_matlab_ddeinit_ddepoke_ddereq(station) -> None:
    """MATLAB's calls through pywin32's dde module: ddepoke must return 1 (acknowledged)."""
    import win32ui  # noqa: F401  (pywin32's dde module refuses to load before win32ui)
    import dde  # isort: skip

    server = dde.CreateServer()
    server.Create("matlab")
    try:
        channel = dde.CreateConversation(server)
        channel.ConnectTo("NFW32", "NFW_DATA")
        channel.Poke("NFW_SERVER", "TUNE ON")  # raises dde.error unless acknowledged
        time.sleep(0.3)
        assert NOVA.match(channel.Request("NFW_SERVER").rstrip("\x00"))
        if wine_version() is None:
            with pytest.raises(dde.error):
                channel.Poke("NFW_SERVER", "NOT A COMMAND")
        else:  # Wine 8.0: a refused poke returns TRUE (result 0), which pywin32 takes as success
            channel.Poke("NFW_SERVER", "NOT A COMMAND")
            channel.Request("NFW_SERVER")  # and the reply after a refusal may be out of step once
        assert NOVA.match(channel.Request("NFW_SERVER").rstrip("\x00"))  # the conversation goes on
    finally:
        server.Destroy()


def test_odd_transactions_get_a_clean_answer_and_the_conversation_goes_on(station, client) -> None:
    from nfwserver.dde.ddeml_client import DdeRefused

    odd = client()
    conv = odd.connect("NFW32", "NFW_DATA")
    odd.poke(conv, "NFW_SERVER", "TUNE ON")
    odd.poke(conv, "NFW_SERVER", b"TRACK ON\x00")  # accepted
    with pytest.raises(DdeRefused):
        odd.request(conv, "TRACK ON")  # not an item: refused
    assert NOVA.match(request_after_refusal(odd, conv, "NFW_SERVER"))
    with pytest.raises(DdeRefused):
        odd.execute(conv, "NFW_SERVER")  # not a command: refused
    assert NOVA.match(request_after_refusal(odd, conv, "NFW_SERVER"))
    odd.poke(conv, "NFW_SERVER", "TRACK OFF")
    assert NOVA.match(request_after_refusal(odd, conv, "NFW_SERVER"))
