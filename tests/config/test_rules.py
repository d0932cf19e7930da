"""Each validation rule, with hand-written TOML: only real problems, each named once, with what is valid."""

from __future__ import annotations

import pytest

from nfwserver.config.loader import ConfigError, load_config, observer_hint, parse_config
from nfwserver.config.table import SECTION_NAMES, STANDARD_BAUD_RATES, keys_of


def problems(text: str, base=None) -> list[str]:
    with pytest.raises(ConfigError) as info:
        parse_config(text, "cfg.toml", base)
    return info.value.problems


# --- issue 14 item 5: configuration errors name only real problems -------------------------------------------------

def test_a_typo_is_the_only_problem_and_lists_the_valid_keys() -> None:
    found = problems("[server]\nratehz = 5\nsatellite = 27607\n")
    assert found == [f"[server] ratehz: unknown key (did you mean rate_hz? valid keys: {', '.join(keys_of('server'))})"]


def test_a_typo_in_a_pair_of_keys_does_not_also_report_the_other_as_missing() -> None:
    # "latitude" for latitude_deg: the section has longitude_deg alone, which would otherwise be "incomplete".
    found = problems("[observer]\nlatitude = 52.2\nlongitude_deg = 0.12\n")
    assert len(found) == 1 and found[0].startswith("[observer] latitude: unknown key (did you mean latitude_deg?")
    found = problems("[easycomm]\nenabled = true\ndevise = '/dev/ttyUSB0'\n")
    assert len(found) == 1 and "did you mean device?" in found[0]
    found = problems("[radio]\nstep_hz = 500\nknob_tolerance = 1000\n")
    assert len(found) == 1 and "[radio] knob_tolerance: unknown key" in found[0]


def test_an_unknown_section_lists_the_valid_sections() -> None:
    found = problems("[rotator]\nbackend = 'sim'\n")
    assert found == [f"[rotator]: unknown section (did you mean rotor? valid sections: {', '.join(SECTION_NAMES)})"]
    assert "tcp" in SECTION_NAMES and "easycomm" in SECTION_NAMES


def test_a_missing_horizon_file_is_one_sentence(tmp_path) -> None:
    assert problems('[horizon]\nfile = "skyline.txt"\n', tmp_path) == \
        [f"[horizon] file: {tmp_path / 'skyline.txt'} does not exist"]


def test_a_missing_element_file_is_one_sentence(tmp_path) -> None:
    (tmp_path / "a.txt").write_text("")
    assert problems('[elements]\nfiles = ["a.txt", "b.txt"]\n', tmp_path) == \
        [f"[elements] files: {tmp_path / 'b.txt'} does not exist"]


def test_a_bad_horizon_line_names_the_file_and_line(tmp_path) -> None:
    (tmp_path / "h.txt").write_text("0 5\n90 north\n")
    found = problems('[horizon]\nfile = "h.txt"\n', tmp_path)
    assert found == [f"[horizon] file: {tmp_path / 'h.txt'} line 2: '90 north' is not two numbers"]


def test_load_config_records_the_file_and_the_observer_hint_names_it(tmp_path) -> None:
    path = tmp_path / "station.toml"
    path.write_text("[server]\nrate_hz = 10\n")
    config = load_config(path)
    assert config.path == str(path) and config.source == str(path)
    assert f"Set [observer] location in {path}." in observer_hint(config)
    assert parse_config("").path is None
    assert "config init" in observer_hint(parse_config(""))


# --- issue 18 items 6 and 15 --------------------------------------------------------------------------------------

CHANNEL = '[[satellites.channels]]\ncatalog_number = 25544\nname = "ISS"\ndownlink_hz = 437800000\n'


@pytest.mark.parametrize(("extra", "reason"), [
    ("downlink_correction_hz = inf\n", "downlink_correction_hz: must be a finite number of Hz"),
    ("uplink_hz = nan\n", "uplink_hz: must be a finite number of Hz"),
    ('hold = "sideways"\n', "hold must be one of satellite, uplink, downlink"),
    ("uplink_hz = 10\n", "uplink_hz 10 is outside 100 kHz..300 GHz"),
    ('downlink_mode = 5\n', "downlink_mode: must be a string"),
    ('inverting = "yes"\n', "inverting: must be true or false"),
    ('downlink = 1\n', "unknown key downlink (valid keys: catalog_number, name, downlink_hz"),
])
def test_a_bad_channel_is_one_problem_naming_the_entry(extra, reason) -> None:
    found = problems(CHANNEL + extra)
    assert len(found) == 1
    assert found[0].startswith("[[satellites.channels]] #1 (catalog_number 25544): ") and reason in found[0]


def test_every_bad_channel_entry_is_reported() -> None:
    text = CHANNEL + "[[satellites.channels]]\ncatalog_number = -3\ndownlink_hz = 1\n" + CHANNEL + "hold = 'x'\n"
    found = problems(text)
    assert [p.split(":")[0] for p in found] == ["[[satellites.channels]] #2 (catalog_number -3)",
                                                "[[satellites.channels]] #3 (catalog_number 25544)"]


def test_good_channels_replace_and_add_to_the_built_in_ones() -> None:
    config = parse_config(CHANNEL + '[[satellites.channels]]\ncatalog_number = 99999\ndownlink_hz = 145900000\n'
                          'downlink_mode = "USB"\n')
    assert config.channels[25544].name == "ISS" and config.channels[25544].uplink_hz is None
    assert config.channels[99999].downlink_mode == "USB" and config.channels[99999].name == "99999"
    assert 27607 in config.channels  # built-in kept


@pytest.mark.parametrize("host", ["0.0.0.0", "::", "192.168.1.5", "station.example.org"])
def test_a_non_loopback_tcp_host_is_accepted_with_a_warning(host) -> None:
    config = parse_config(f'[tcp]\nenabled = true\nhost = "{host}"\n')
    assert config.tcp.host == host
    assert len(config.warnings) == 1 and config.warnings[0].startswith(f'[tcp] host = "{host}": ')
    if host in ("0.0.0.0", "::"):
        assert "every network interface" in config.warnings[0]


@pytest.mark.parametrize("host", ["127.0.0.1", "127.0.0.2", "::1", "localhost"])
def test_loopback_listeners_and_disabled_ones_do_not_warn(host) -> None:
    assert parse_config(f'[tcp]\nenabled = true\nhost = "{host}"\n').warnings == ()
    assert parse_config(f'[dialects]\npredict_udp = true\npredict_host = "{host}"\n').warnings == ()
    assert parse_config('[tcp]\nhost = "0.0.0.0"\n[dialects]\npredict_host = "0.0.0.0"\n').warnings == ()


def test_predict_on_every_interface_warns_about_amplification() -> None:
    config = parse_config('[dialects]\npredict_udp = true\npredict_host = "0.0.0.0"\n')
    assert len(config.warnings) == 1
    assert config.warnings[0].startswith('[dialects] predict_host = "0.0.0.0": it listens on every network interface')
    assert "larger than the requests" in config.warnings[0]


# --- issue 13 items 1, 3, 4: [tcp], [easycomm] ---------------------------------------------------------------------

def test_tcp_defaults_are_nova_port_on_loopback_only() -> None:
    tcp = parse_config("").tcp
    assert (tcp.enabled, tcp.host, tcp.port) == (False, "127.0.0.1", 8090)
    assert tcp.allows("127.0.0.1") and tcp.allows("::1")
    assert not tcp.allows("127.0.0.2") and not tcp.allows("10.1.2.3")  # 127.0.0.2 stands for a foreign host


def test_tcp_allow_takes_addresses_and_networks() -> None:
    tcp = parse_config('[tcp]\nallow = ["127.0.0.1", "10.0.0.0/8", "192.168.1.7/24", "2001:db8::/32"]\n').tcp
    assert tcp.allow == ("127.0.0.1/32", "10.0.0.0/8", "192.168.1.0/24", "2001:db8::/32")
    assert tcp.allows("10.200.3.4") and tcp.allows("192.168.1.200") and tcp.allows("2001:db8::5")
    assert tcp.allows("::ffff:10.1.2.3")  # an IPv4 peer on a dual-stack socket
    assert not tcp.allows("192.168.2.1") and not tcp.allows("::1") and not tcp.allows("not an address")


@pytest.mark.parametrize(("text", "reason"), [
    ('allow = ["10.0.0.300"]', '[tcp] allow: "10.0.0.300" is not an IP address or network'),
    ('allow = "127.0.0.1"', "[tcp] allow: must be a list of addresses or networks"),
    ("allow = [5]", "[tcp] allow: 5 is not an IP address or network"),
    ("port = 70000", "[tcp] port: 70000 is outside 0..65535"),
    ('host = ""', "[tcp] host: must be a host name or address"),
    ('host = "0.0.0.0 1"', "[tcp] host: must be a host name or address"),
])
def test_tcp_problems(text, reason) -> None:
    found = problems(f"[tcp]\n{text}\n")
    assert len(found) == 1 and found[0].startswith(reason)


def test_easycomm_defaults_and_a_full_section() -> None:
    ec = parse_config("").easycomm
    assert (ec.enabled, ec.device, ec.baud, ec.rate_hz, ec.uplink) == (False, None, 9600, 2.0, "range-rate")
    ec = parse_config('[easycomm]\nenabled = true\ndevice = "/dev/ttyUSB0"\nbaud = 115200\nrate_hz = 0.5\n'
                      'uplink = "doppler"\n').easycomm
    assert (ec.enabled, ec.device, ec.baud, ec.rate_hz, ec.uplink) == (True, "/dev/ttyUSB0", 115200, 0.5, "doppler")


@pytest.mark.parametrize(("text", "reason"), [
    ("enabled = true", '[easycomm] device: required when enabled (e.g. "/dev/ttyUSB0")'),
    ('device = "/dev/ttyS0"\nbaud = 9601',
     "[easycomm] baud: must be one of " + ", ".join(str(b) for b in STANDARD_BAUD_RATES)),
    ('baud = "9600"', "[easycomm] baud: must be one of " + ", ".join(str(b) for b in STANDARD_BAUD_RATES)),
    ("rate_hz = 20", "[easycomm] rate_hz: 20 is outside 0.5..10"),
    ("rate_hz = 0.1", "[easycomm] rate_hz: 0.1 is outside 0.5..10"),
    ('uplink = "frequency"', '[easycomm] uplink: must be one of "range-rate", "doppler"'),
    ('device = ""', "[easycomm] device: must be 1 to 4096 printable characters"),
])
def test_easycomm_problems(text, reason) -> None:
    assert problems(f"[easycomm]\n{text}\n") == [reason]


def test_a_device_may_be_absent_at_start() -> None:
    """A USB adaptor may be plugged in later: the output copes, so the configuration does not require it."""
    assert parse_config('[easycomm]\nenabled = true\ndevice = "/dev/does-not-exist"\n').easycomm.enabled


def test_mode_schedules_are_checked_and_reach_the_config() -> None:
    # InstantTrack: a schedule is three-digit phases (256ths of an orbit) each followed by the mode in force.
    from nfwserver.config.loader import ConfigError, parse_config

    config = parse_config('[satellites]\nschedules = { 7530 = "000B128A" }\n')
    assert config.schedules == {7530: "000B128A"}
    for bad in ('{ 7530 = "B000" }', '{ 7530 = "128A000B" }', '{ AO7 = "000B" }', '"000B"'):
        with pytest.raises(ConfigError, match=r"\[satellites\] schedules"):
            parse_config(f"[satellites]\nschedules = {bad}\n")
