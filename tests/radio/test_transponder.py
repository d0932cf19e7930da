"""Channel arithmetic: which side holds still, inverting transponders, corrections."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from nfwserver.channels.channel import Channel
from nfwserver.tracking.doppler import SPEED_OF_LIGHT_KM_S as C

LINEAR = Channel("RS-44", downlink_hz=435_640_000, uplink_hz=145_965_000, downlink_mode="USB", uplink_mode="LSB",
                 inverting=True)
FM = Channel("SO-50", downlink_hz=436_795_000, uplink_hz=145_850_000)


def test_constant_satellite_frequency() -> None:
    rx, tx = FM.ground_frequencies(-5.0)  # approaching: downlink heard high, uplink sent low
    assert rx == pytest.approx(436_795_000 * (1 + 5.0 / C))
    assert tx == pytest.approx(145_850_000 * (1 - 5.0 / C))
    assert rx > 436_795_000 and tx < 145_850_000


def test_inverting_transponder_moves_uplink_against_downlink() -> None:
    rx0, tx0 = LINEAR.ground_frequencies(2.0)
    rx1, tx1 = LINEAR.with_offset(1000.0).ground_frequencies(2.0)
    assert rx1 - rx0 == pytest.approx(1000.0 * (1 - 2.0 / C))
    assert tx1 - tx0 == pytest.approx(-1000.0 * (1 + 2.0 / C))
    plain = Channel("lin", 435_640_000, 145_965_000, inverting=False).with_offset(1000.0)
    assert plain.ground_frequencies(2.0)[1] - Channel("lin", 435_640_000, 145_965_000).ground_frequencies(2.0)[1] > 0


@given(st.floats(-8, 8), st.sampled_from(["satellite", "uplink", "downlink"]), st.booleans())
def test_every_hold_mode_puts_the_signal_through_the_transponder(rr, hold, inverting) -> None:
    ch = Channel("x", 435_640_000, 145_965_000, inverting=inverting, hold=hold, passband_offset_hz=2500.0)
    rx, tx = ch.ground_frequencies(rr)
    heard_at_satellite = tx / (1 + rr / C)
    comes_down = ch.convert(heard_at_satellite) * (1 - rr / C)
    assert comes_down == pytest.approx(rx, abs=1e-3)
    if hold == "uplink":
        assert tx == pytest.approx(ch.satellite_uplink_hz())
    if hold == "downlink":
        assert rx == pytest.approx(ch.satellite_downlink_hz())


def test_beacon_and_validation() -> None:
    rx, tx = Channel("beacon", 145_800_000).ground_frequencies(1.0)
    assert tx is None and rx < 145_800_000
    with pytest.raises(ValueError):
        Channel("bad", 10.0)
    with pytest.raises(ValueError):
        Channel("bad", 145e6, hold="sideways")
    with pytest.raises(ValueError):
        Channel("bad", float("nan"))
