"""The campaign behind ``python -m bench reliability``, run tiny (seconds, bounded loops) so its own code is
tested: every family runs against a real Station and finds nothing; the counters it relies on do count
a logged traceback, a dying thread and a missing reply."""

from __future__ import annotations

import logging
import threading

from bench.bench_reliability import format_report, run_campaign
from bench.campaign.input_families import expected_replies
from bench.campaign.station_rig import hamlib_available
from bench.campaign.tally import Budget, Tally, run_family


def test_a_tiny_campaign_runs_every_family_and_finds_nothing(tmp_path) -> None:
    budget = Budget.smoke()
    tallies = run_campaign(budget, tmp_path)
    by_name = {t.family: t for t in tallies}
    assert len(tallies) == 15
    for tally in tallies:
        assert tally.clean, (tally.family, tally.crashes, tally.tracebacks, tally.lost, tally.notes)
        if tally.family != "rotctld/rigctld killed and restarted" or hamlib_available():
            assert tally.tried > 0, tally.family
    assert by_name["element files: load_elements"].tried == budget.elements
    assert by_name["Nova lines over TCP"].extra["replies owed / received"].split(" / ")[0] == \
        by_name["Nova lines over TCP"].extra["replies owed / received"].split(" / ")[1]
    assert by_name["TCP: web pages' requests (cross-protocol), 8 addresses"].extra[
        "closed as HTTP (tcp_http_closed)"] == budget.http_requests
    realtime = tallies[-1]
    assert realtime.extra["ticks"] >= 50 * budget.realtime_s * 0.8  # 50 Hz for the whole run
    assert realtime.extra["tick failures"] == 0 and len(realtime.extra["rss samples"]) >= 2
    report = format_report(tallies, budget, 1.0)
    assert report.startswith("## Reliability campaign") and "| **total** |" in report


def test_the_tally_counts_logged_tracebacks_and_dying_threads() -> None:
    def body(tally: Tally) -> None:
        tally.tried += 1
        try:
            raise ValueError("boom")
        except ValueError:
            logging.getLogger("nfwserver.somewhere").exception("it failed")
        thread = threading.Thread(target=lambda: 1 / 0, name="doomed")
        thread.start()
        thread.join()
        raise RuntimeError("escaped")

    tally = run_family(Tally("meta"), body)
    assert tally.tracebacks == 1 and tally.crashes == 2  # the dying thread and the escaping exception
    assert any("doomed" in note for note in tally.notes) and not tally.clean


def test_the_independent_tcp_splitter_counts_owed_replies() -> None:
    # Lines end at CR LF, CR, LF or NUL; blank lines get no reply; an over-long line gets one refusal.
    assert expected_replies(b"SUMMARY\r\n") == 1
    assert expected_replies(b"  \t \r\n") == 0
    assert expected_replies(b"\x0b\x0c\x1c\x1f \r\n") == 0  # VT, FF and the separators are white space too
    assert expected_replies(b"TUNE ON\rTRACK ON\nSAT=1\x00\r\n") == 3
    assert expected_replies(b" " * 2000 + b"\r\n") == 1
    assert expected_replies(b"A" * 1024 + b"\r\n") == 1


def test_the_cross_protocol_family_sees_commands_run_from_a_request(tmp_path, monkeypatch) -> None:
    """Without the TCP face's HTTP check the family must count the damage (replies, a changed satellite)."""
    from bench.campaign import tcp_attacks

    monkeypatch.setattr("nfwserver.tcp.server.http_in", lambda lines: None)
    tally = run_family(Tally("cross"), lambda t: tcp_attacks.run_cross_protocol(t, 4, 2026, tmp_path))
    assert tally.lost > 0 and not tally.clean, tally
