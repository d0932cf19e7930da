"""Refused commands are logged once per client and then summarised, never once each (a flood of bad pokes
must not flood the log); every one is still an event.  Found by ``python -m bench reliability``: 20,000
fuzzed pokes wrote 14,061 warning lines."""

from __future__ import annotations

import logging

from tests.dde.conftest import make_station


def _refusals(caplog) -> list[str]:
    return [r.getMessage() for r in caplog.records if r.getMessage().startswith("refused command")]


def test_a_flood_of_refused_commands_writes_one_line_then_a_counted_summary(caplog) -> None:
    caplog.set_level(logging.WARNING)
    station = make_station()
    core, clock = station.core, station.clock
    for k in range(200):
        assert not core.command(f"SAT=x{k}", source="dde conv 7").accepted
    assert core.command("BOGUS", source="tcp 127.0.0.1:5000").accepted is False  # another client: at once
    first, other = _refusals(caplog)
    assert "SAT=x0" in first and "dde conv 7" in first and "BOGUS" in other
    clock.advance(61.0)
    core.command("SAT=y", source="dde conv 7")
    lines = _refusals(caplog)
    assert len(lines) == 3 and "199 more like this in the last 61 s" in lines[-1]
    refused = [e for e in core.events.recent() if e.kind == "poke" and e.accepted is False]
    assert len(refused) == 202  # every refusal is recorded
