"""Commands are atomic (issue 24, deliver 2): a poke of several lines is validated whole before any line
takes effect, so a refused poke changes nothing.

Before the command table, ``TUNE ON\\nSAT=99999`` was refused as a whole (the DDE client got
DDE_FNOTPROCESSED) yet switched the feed on: the first line had been applied before the second failed.
"""

from __future__ import annotations

import pytest

from nfwserver.fake_dde import DdeError
from tests.dde.conftest import ISS, make_station


@pytest.mark.parametrize("poke", ["TUNE ON\nSAT=99999", "TUNE ON\r\nSAT=abc", "TRACK ON\nANTAZ=900",
                                  "TUNE ON\nTRACK ON\nBOGUS"])
def test_a_refused_multi_line_poke_changes_nothing(poke: str) -> None:
    station = make_station()
    conv = station.system.connect("NFW32", "NFW_DATA")
    with pytest.raises(DdeError):
        conv.poke("NFW_SERVER", poke)
    station.run(1.0)
    state = station.core.state.snapshot()
    assert (state.feed_on, state.tracking, state.catalog_number) == (False, False, ISS)
    assert conv.request_text("NFW_SERVER") == ""
    refused = [e for e in station.core.events.recent() if e.kind == "poke" and e.accepted is False]
    assert len(refused) == 1


def test_an_accepted_multi_line_poke_applies_every_line_in_order() -> None:
    station = make_station()
    conv = station.system.connect("NFW32", "NFW_DATA")
    conv.poke("NFW_SERVER", "TUNE ON\nTRACK ON\nANTAZ=12.5")
    station.run(1.0)
    state = station.core.state.snapshot()
    assert (state.feed_on, state.tracking) == (True, True)
    assert conv.request_text("NFW_SERVER").startswith("ISS AZ:")
