"""Channel values are checked when the channel is built (issue 18 item 6): a non-finite correction or
an unknown mode is refused with one clear sentence instead of failing on every tick."""

from __future__ import annotations

import math

import pytest

from nfwserver.channels.channel import Channel
from nfwserver.channels.modes import HAMLIB_MODES
from nfwserver.config.loader import ConfigError, parse_config


@pytest.mark.parametrize("field", ["downlink_correction_hz", "uplink_correction_hz"])
@pytest.mark.parametrize("value", [math.inf, -math.inf, math.nan, 2e6, "12"])
def test_corrections_must_be_finite_and_plausible(field: str, value: object) -> None:
    with pytest.raises(ValueError, match=f"channel 'ISS': {field}"):
        Channel("ISS", 437_800_000, 145_990_000, **{field: value})


@pytest.mark.parametrize("value", [math.inf, math.nan])
def test_the_passband_offset_must_be_finite(value: float) -> None:
    with pytest.raises(ValueError, match="passband_offset_hz"):
        Channel("ISS", 437_800_000, 145_990_000, passband_offset_hz=value)
    with pytest.raises(ValueError, match="passband_offset_hz"):
        Channel("ISS", 437_800_000, 145_990_000).with_offset(value)


@pytest.mark.parametrize("field", ["downlink_mode", "uplink_mode"])
@pytest.mark.parametrize("mode", ["NONSENSE", "", "U SB", "USB 0", None, 3])
def test_modes_must_be_hamlib_names(field: str, mode: object) -> None:
    with pytest.raises(ValueError, match=f"{field} .* is not a Hamlib mode"):
        Channel("ISS", 437_800_000, 145_990_000, **{field: mode})


def test_hamlib_names_are_accepted_in_any_case_and_stored_upper_case() -> None:
    channel = Channel("ISS", 437_800_000, 145_990_000, downlink_mode="usb", uplink_mode="Lsb",
                      downlink_correction_hz=-1200.0, uplink_correction_hz=350)
    assert (channel.downlink_mode, channel.uplink_mode) == ("USB", "LSB")


def test_the_configuration_reports_a_bad_channel_with_its_key() -> None:
    text = ('[[satellites.channels]]\ncatalog_number = 25544\ndownlink_hz = 437800000\n'
            'downlink_correction_hz = inf\ndownlink_mode = "NONSENSE"\n')
    with pytest.raises(ConfigError, match=r"#1 \(catalog_number 25544\): downlink_correction_hz: must be a finite"):
        parse_config(text)
    text = text.replace("downlink_correction_hz = inf\n", "")
    with pytest.raises(ConfigError, match=r"#1 \(catalog_number 25544\).*NONSENSE"):
        parse_config(text)


def test_every_accepted_mode_is_one_rigctld_reads_back_and_an_unknown_one_is_ignored(rigctld) -> None:
    """The real daemon is the oracle: each accepted name changes the dummy rig's mode to a Hamlib name;
    ``NONSENSE`` is answered ``RPRT 0`` and changes nothing -- why names are checked before sending."""
    for mode in sorted(HAMLIB_MODES):
        assert rigctld.query("M CW 0") == ["RPRT 0"]
        assert rigctld.query(f"M {mode} 0") == ["RPRT 0"]
        read_back = rigctld.query("m", 2)[0]
        assert read_back in HAMLIB_MODES and (read_back != "CW" or mode == "CW"), (mode, read_back)
    assert rigctld.query("M NONSENSE 0") == ["RPRT 0"]
    assert rigctld.query("m", 2)[0] == "WFM"  # the last mode set (sorted order), unchanged
