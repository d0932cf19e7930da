"""``nfwserver simulate --client/--link``: each client's transaction pattern, and the dialects' items.

Expected sequences are written from the patterns DESIGN.md §3 records for each client (WiSP polls
every 3 s and re-pokes TUNE ON when a reply lacks AH:, Delphi requests per warm-link notification,
NDde holds a hot link and requests every second, MATLAB pokes once then requests).
"""

from __future__ import annotations

import re
from datetime import datetime, timezone

import pytest

from nfwserver.cli import main
from tests.conftest import DATA
from tests.dde.conftest import ISS_PASS, OBSERVER

START = ISS_PASS.tca.strftime("%Y-%m-%dT%H:%M:%S")
BASE = ["simulate", "--elements", str(DATA / "visual.txt"), "--sat", "25544",
        "--observer", f"{OBSERVER.latitude_deg},{OBSERVER.longitude_deg},{OBSERVER.altitude_m}", "--start", START]
NOVA = re.compile(r"^ISS AZ:\d+\.\d EL:-?\d+\.\d RR:-?\d+\.\d{10} AH:Y$")


def _run(capsys, *extra: str) -> list[tuple[float, str, str]]:
    """(seconds after the start, kind, text) per line."""
    assert main([*BASE, *extra]) == 0
    rows = []
    start = datetime.fromisoformat(START).replace(tzinfo=timezone.utc)
    for line in capsys.readouterr().out.splitlines():
        when, kind, text = line.split("\t")
        at = datetime.strptime(when, "%Y-%m-%dT%H:%M:%S.%fZ").replace(tzinfo=timezone.utc)
        rows.append((round((at - start).total_seconds(), 3), kind, text))
    return rows


def _shape(rows: list[tuple[float, str, str]]) -> list[tuple[float, str, str]]:
    """Rows with Nova strings replaced by 'DATA', so sequences can be compared."""
    return [(t, kind, "DATA" if NOVA.match(text) else text) for t, kind, text in rows]


def test_wisp_polls_every_3_s_and_repokes_tune_on_when_ah_is_missing(capsys) -> None:
    rows = _run(capsys, "--client", "wisp", "--rate", "1", "--duration", "10", "--poke", "4:TUNE OFF")
    assert _shape(rows) == [
        (0.0, "poke", "TUNE ON"), (0.0, "reply", "DATA"),  # TUNE ON first: the first TUNE poke is OFF, later
        (3.0, "reply", "DATA"), (4.0, "poke", "TUNE OFF"),
        (6.0, "reply", "(empty)"), (7.0, "poke", "TUNE ON"),
        (9.0, "reply", "DATA"),
    ]
    rows = _run(capsys, "--client", "wisp", "--rate", "1", "--duration", "4", "--poll", "2")
    assert _shape(rows) == [(0.0, "poke", "TUNE ON"), (0.0, "reply", "DATA"), (2.0, "reply", "DATA"),
                            (4.0, "reply", "DATA")]


def test_wisp_with_interval_0_and_delphi_request_on_each_warm_notification(capsys) -> None:
    expected_ticks = [(t, kind, text) for t in (0.0, 1.0, 2.0)
                      for kind, text in (("notify", "NFW_SERVER"), ("reply", "DATA"))]
    rows = _run(capsys, "--client", "delphi", "--rate", "1", "--duration", "2")
    # The request right after TUNE ON, before the first tick, gets the string (#34 item 5), not "".
    assert _shape(rows) == [(0.0, "poke", "TUNE ON"), (0.0, "reply", "DATA"), *expected_ticks]
    rows = _run(capsys, "--client", "wisp", "--poll", "0", "--rate", "1", "--duration", "2")
    assert _shape(rows) == [(0.0, "poke", "TUNE ON"), *expected_ticks]


def test_ndde_hot_link_and_requests_every_second(capsys) -> None:
    rows = _run(capsys, "--client", "ndde", "--rate", "2", "--duration", "2")
    assert _shape(rows) == [(0.0, "poke", "TUNE ON"), (0.0, "data", "DATA"), (0.0, "reply", "DATA"),
                            (0.5, "data", "DATA"), (1.0, "data", "DATA"), (1.0, "reply", "DATA"),
                            (1.5, "data", "DATA"), (2.0, "data", "DATA"), (2.0, "reply", "DATA")]
    # The reply to a request is the string the hot link carried for the same tick.
    assert rows[1][2] == rows[2][2] and rows[4][2] == rows[5][2]


def test_matlab_pokes_once_then_requests_and_never_repokes(capsys) -> None:
    rows = _run(capsys, "--client", "matlab", "--rate", "1", "--duration", "6")
    assert _shape(rows) == [(0.0, "poke", "TUNE ON"), (0.0, "reply", "DATA"), (3.0, "reply", "DATA"),
                            (6.0, "reply", "DATA")]
    rows = _run(capsys, "--client", "matlab", "--rate", "1", "--duration", "6", "--poke", "0:TUNE OFF")
    assert _shape(rows) == [(0.0, "poke", "TUNE OFF"), (0.0, "reply", "(empty)"), (3.0, "reply", "(empty)"),
                            (6.0, "reply", "(empty)")]


def test_warm_link_prints_notifications_only(capsys) -> None:
    rows = _run(capsys, "--client", "warm", "--rate", "2", "--duration", "1")
    assert rows == [(0.0, "poke", "TUNE ON")] + [(t, "notify", "NFW_SERVER") for t in (0.0, 0.5, 1.0)]


def test_link_watches_the_other_names_and_the_dialects(capsys) -> None:
    rows = _run(capsys, "--client", "warm", "--link", "NFW_SERVER|NFW_DATA!NFW_DATA", "--duration", "0.2")
    assert rows[1:] == [(0.0, "notify", "NFW_DATA"), (0.2, "notify", "NFW_DATA")]
    # Orbitron's TrackingData: SN<name> AZ EL DN UP (DESIGN.md §3), today's two-column format (hot default).
    assert main([*BASE, "--link", "Orbitron|Tracking!TrackingData", "--duration", "2"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines and all(re.match(r"^\S+Z\tSNISS\S* AZ\d+\.\d EL\d+\.\d DN\d+ UP\d+", line) for line in lines)
    rows = _run(capsys, "--client", "delphi", "--link", "Orbitron|Tracking!TrackingDataEx", "--duration", "1")
    assert rows[0] == (0.0, "poke", "TUNE ON (on NFW32|NFW_DATA!NFW_SERVER)")  # the dialects take no pokes
    assert any(kind == "reply" and text.startswith('SN"ISS') for _, kind, text in rows)
    rows = _run(capsys, "--client", "ndde", "--link", "WXtrack|Tracking!Tracking", "--duration", "1")
    assert any(kind == "reply" and text.startswith("SNISS") for _, kind, text in rows)
    # SatPC32 ends its strings in CR LF, shown escaped so each transaction stays one line.
    rows = _run(capsys, "--client", "matlab", "--link", "SatPC32|SatPcDdeConv!SatPcDdeItem", "--duration", "1")
    replies = [text for _, kind, text in rows if kind == "reply"]
    assert replies and all(re.match(r"^SNISS AZ\d+\.\d EL\d+\.\d UP\d+ UM\S* DN\d+ DM\S* MA\d+\.\d\\r\\n$", text)
                           for text in replies)


@pytest.mark.parametrize("link", ["NFW32|NFW_DATA!NFW_SERVER", "Orbitron|Tracking!TrackingDataEx"])
def test_every_poke_takes_the_path_of_a_dde_clients_poke(capsys, monkeypatch, link) -> None:
    """The automatic TUNE ON and each --poke reach the station through Nova's DDE service, as a client's poke does,
    on a dialect link too (before, there they went to the core's command method, behind the DDE service)."""
    from nfwserver.dde.nova_service import NovaDdeService

    poked: list[str] = []
    on_poke = NovaDdeService.on_poke

    def counting(self, conv, topic, item, fmt, data):
        poked.append(data.rstrip(b"\x00").decode("ascii"))
        return on_poke(self, conv, topic, item, fmt, data)

    monkeypatch.setattr(NovaDdeService, "on_poke", counting)
    _run(capsys, "--client", "delphi", "--link", link, "--duration", "2", "--poke", "1:SAT=694")
    assert poked == ["TUNE ON", "SAT=694"]
