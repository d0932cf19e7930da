"""OrbitDRV's status word and Nova's commands on the station core, checked against the seeds' own words.

Every expected value here comes from the spec text quoted beside it
(seeds/orbitdrv-interrupt-interface.txt), not from the code's output.
"""

from __future__ import annotations

from datetime import timedelta

import pytest

from nfwserver.core.status import INTERFACE_VERSION, StatusBit
from nfwserver.fake_dde.errors import DMLERR_NOTPROCESSED, DdeError
from nfwserver.tracking.catalog import Catalog
from tests.dde.conftest import CATALOG, ISS, ISS_PASS, make_station

DEAD = 99999  # an element set SGP4 cannot propagate (built below)


def _station_with_dead_satellite():
    """A station whose catalog also holds ISS's elements dated ten years earlier: SGP4 reports it decayed."""
    from nfwserver.tracking.elements import load_elements
    from nfwserver.tracking.tle import tle_checksum

    iss = CATALOG.get(ISS).elements
    l1 = iss.line1[:2] + f"{DEAD:05d}" + iss.line1[7:18] + "16" + iss.line1[20:68]
    l2 = iss.line2[:2] + f"{DEAD:05d}" + iss.line2[7:68]
    dead = load_elements(f"DEAD\n{l1}{tle_checksum(l1)}\n{l2}{tle_checksum(l2)}\n").sets[0]
    return make_station(catalog=Catalog([*(s.elements for s in CATALOG), dead]))  # never the shared CATALOG


def test_defaults_on_loading() -> None:
    # "0004 Tracking is currently disabled. ... It is also the default condition on loading"
    # "0008 Tuning is currently disabled. ... It is also the default condition on loading"
    sample = make_station().core.tick()
    assert sample.status & StatusBit.TRACKING_DISABLED
    assert sample.status & StatusBit.TUNING_DISABLED
    # "The interface described by this version of this document returns 01 in BH."
    assert sample.interface_version == INTERFACE_VERSION == 1


def test_tuning_bit_is_the_radios_not_the_dde_feed() -> None:
    # Function FD "controls whether OrbitDRV provides range rate (Doppler shift) updates to the Radio Driver".
    station = make_station(start=ISS_PASS.tca)
    core = station.core
    core.command("TUNE ON")  # Nova's DDE output, not OrbitDRV tuning
    sample = core.tick()
    assert sample.text and sample.feed_on
    assert sample.status & StatusBit.TUNING_DISABLED
    core.set_doppler(True)
    sample = core.tick()
    assert not sample.status & StatusBit.TUNING_DISABLED and sample.doppler_on


def test_track_on_is_ignored_without_station_or_satellite() -> None:
    # Function FE: "The enable call will be ignored if the station or satellite parameters have not been set."
    station = make_station(satellite=None)
    result = station.core.command("TRACK ON")
    assert result.accepted and result.note and "satellite" in result.note
    assert station.core.tick().status & StatusBit.TRACKING_DISABLED
    assert station.core.tick().status & StatusBit.SATELLITE_MISSING
    station.core.command(f"SAT={ISS}")
    assert station.core.command("TRACK ON").ok
    assert not station.core.tick().status & StatusBit.TRACKING_DISABLED


def test_not_in_view_only_while_tracking() -> None:
    # "0020 The satellite is not currently in view. This bit is only valid if tracking is enabled."
    core = make_station().core
    assert not core.tick(ISS_PASS.aos - timedelta(minutes=5)).status & StatusBit.NOT_IN_VIEW
    core.command("TRACK ON")
    assert core.tick(ISS_PASS.aos - timedelta(minutes=5)).status & StatusBit.NOT_IN_VIEW
    assert not core.tick(ISS_PASS.tca).status & StatusBit.NOT_IN_VIEW


def test_not_recomputed_after_a_parameter_change() -> None:
    # "0040 The satellite's position has not been recomputed since the last parameter change."
    core = make_station().core
    core.tick()
    assert not core.tracker.status_word() & StatusBit.NOT_RECOMPUTED
    other = next(s.catalog_number for s in CATALOG if s.catalog_number != ISS)
    assert core.command(f"SAT={other}").ok
    assert core.tracker.status_word() & StatusBit.NOT_RECOMPUTED
    core.tick()
    assert not core.tracker.status_word() & StatusBit.NOT_RECOMPUTED


def test_arithmetic_error_belongs_to_the_tick_it_happened_in() -> None:
    # "0010 An arithmetic error has occurred."  OrbitDRV then computed nothing until an enable call; an
    # unattended server must not go silent for good on one bad instant (issue: unattended station), so
    # the bit describes the tick that failed and the feed resumes on the first good one, no command needed.
    core = make_station().core
    core.command("TUNE ON")
    good = core.tick(ISS_PASS.tca)
    far = core.tick(ISS_PASS.tca + timedelta(days=3650))  # a clock step ten years on: SGP4 gives up
    assert far.status & StatusBit.ARITHMETIC_ERROR and far.text == "" and far.error
    assert core.current_text() == ""
    assert list(core.health.faults()) == ["tracking"]
    assert "cannot compute ISS" in core.health.faults()["tracking"]
    again = core.tick(ISS_PASS.tca)  # the clock is back: the very next tick publishes
    assert not again.status & StatusBit.ARITHMETIC_ERROR and not again.error
    assert again.text == good.text and core.current_text() == good.text
    assert core.health.faults() == {}


def test_sat_of_a_set_that_cannot_be_computed_now_is_refused_and_the_feed_stays() -> None:
    # Never a silent OK followed by nothing: the poke is refused (DDE_FNOTPROCESSED, a bad subfunction)
    # with the reason, and the satellite being published stays selected.
    station = _station_with_dead_satellite()
    core = station.core
    core.command("TUNE ON")
    before = core.tick()
    assert before.text.startswith("ISS ")
    result = core.command(f"SAT={DEAD}")
    assert not result.accepted and result.status & StatusBit.BAD_SUBFUNCTION
    assert result.note is not None and "cannot be computed now" in result.note and "decayed" in result.note
    assert core.state.snapshot().catalog_number == ISS
    assert core.tick().text.startswith("ISS ")
    conv = station.system.connect("NFW32", "NFW_DATA")
    with pytest.raises(DdeError) as refused:  # DDE_FNOTPROCESSED on the wire too
        conv.poke("NFW_SERVER", f"SAT={DEAD}")
    assert refused.value.code == DMLERR_NOTPROCESSED
    assert conv.request_text("NFW_SERVER").startswith("ISS ")


def test_no_string_of_the_previous_satellite_after_sat_change() -> None:
    # Issue: a client must never get data for a satellite that is no longer selected.
    station = _station_with_dead_satellite()
    core = station.core
    core.command("TUNE ON")
    assert core.tick(ISS_PASS.tca).text.startswith("ISS ")
    assert core.select_satellite(DEAD, source="console")  # the console's picker selects without computing
    assert core.current_text() == ""  # at once, before any tick
    sample = core.tick(ISS_PASS.tca)
    assert sample.status & StatusBit.ARITHMETIC_ERROR and sample.text == "" and core.current_text() == ""
    conv = station.system.connect("NFW32", "NFW_DATA")
    assert conv.request_text("NFW_SERVER") == ""


def test_bad_function_and_subfunction_bits() -> None:
    # "4000 This command had a bad function code in AH."  "8000 This command had a bad subfunction code in AL."
    core = make_station().core
    unknown = core.command("FOO BAR")
    assert not unknown.accepted and unknown.status & StatusBit.BAD_FUNCTION
    assert not unknown.status & StatusBit.BAD_SUBFUNCTION
    bad_arg = core.command("ANTAZ=900")
    assert not bad_arg.accepted and bad_arg.status & StatusBit.BAD_SUBFUNCTION
    assert not bad_arg.status & StatusBit.BAD_FUNCTION
    assert core.command("SAT=1").status & StatusBit.BAD_SUBFUNCTION  # no such satellite: a bad argument
    good = core.command("TUNE ON")
    assert good.ok and not good.status & (StatusBit.BAD_FUNCTION | StatusBit.BAD_SUBFUNCTION)
