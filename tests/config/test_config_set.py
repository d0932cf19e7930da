"""``config set``, ``config init --locator``, a BOM, and ``config show`` as written (issue 25 item 6)."""

from __future__ import annotations

import os
import stat

import pytest

from nfwserver.cli import main
from nfwserver.config.loader import load_config
from nfwserver.tracking.observer import parse_observer


@pytest.fixture
def station_file(tmp_path):
    path = tmp_path / "station.toml"
    assert main(["config", "init", "--config", str(path), "--locator", "JO01ab"]) == 0
    return path


def test_init_with_a_locator_or_coordinates_configures_the_observer(tmp_path, station_file) -> None:
    config = load_config(station_file)
    expected = parse_observer("JO01ab")
    assert config.observer_configured and config.observer == expected
    other = tmp_path / "coords.toml"
    assert main(["config", "init", "--config", str(other), "--lat", "-33.87", "--lon", "151.21", "--alt", "40"]) == 0
    observer = load_config(other).observer
    assert (observer.latitude_deg, observer.longitude_deg, observer.altitude_m) == (-33.87, 151.21, 40.0)
    assert main(["config", "init", "--config", str(tmp_path / "x.toml"), "--lat", "10"]) == 1


def test_set_keeps_comments_and_layout_and_validates_the_whole_file(station_file, capsys) -> None:
    before = station_file.read_text()
    comments = [line for line in before.splitlines() if line.startswith("#")]
    assert main(["config", "set", "--config", str(station_file), "tcp.enabled", "true"]) == 0
    after = station_file.read_text()
    assert load_config(station_file).tcp.enabled
    kept = [line for line in after.splitlines() if line.startswith("#")]
    assert set(kept) <= set(comments) and len(comments) - len(kept) <= 1  # at most the commented example
    assert after.count("\n") >= before.count("\n") - 1
    assert main(["config", "set", "--config", str(station_file), "satellites.favourites", "[25544, 7530]"]) == 0
    assert load_config(station_file).favourites == (25544, 7530)


@pytest.mark.parametrize(("key", "value", "says"), [("tcp.port", "99999", "outside 0..65535"),
                                                      ("tcp.enable", "true", "did you mean tcp.enabled"),
                                                      ("rotor.backend", "telepathy", "rotor")])
def test_a_refused_value_changes_nothing(station_file, capsys, key: str, value: str, says: str) -> None:
    before = station_file.read_bytes()
    assert main(["config", "set", "--config", str(station_file), key, value]) == 1
    assert says in capsys.readouterr().err
    assert station_file.read_bytes() == before


def test_set_keeps_the_file_permissions(station_file) -> None:
    os.chmod(station_file, 0o640)
    assert main(["config", "set", "--config", str(station_file), "server.rate_hz", "2"]) == 0
    assert stat.S_IMODE(station_file.stat().st_mode) == 0o640
    assert load_config(station_file).server.rate_hz == 2


def test_a_file_with_a_utf8_bom_is_read_and_edited(tmp_path) -> None:
    path = tmp_path / "bom.toml"
    path.write_bytes(b"\xef\xbb\xbf[observer]\nlocation = \"JO01ab\"\n")
    assert load_config(path).observer_configured
    assert main(["config", "set", "--config", str(path), "tcp.enabled", "true"]) == 0
    assert load_config(path).tcp.enabled and load_config(path).observer_configured


def test_show_prints_values_as_written(station_file, capsys) -> None:
    capsys.readouterr()
    assert main(["config", "show", "--config", str(station_file)]) == 0
    out = capsys.readouterr().out
    assert 'location = "JO01ab"' in out
    assert "0.041666666666666664" not in out  # the locator's longitude is shown rounded, as derived
    assert "longitude_deg = 0.04166666667  # from location" in out


@pytest.mark.parametrize(("key", "value", "says"), [
    ("tcp.port", "9001", "a running station needs a restart to apply [tcp]"),
    ("rotor.backend", "sim", "a running station needs a restart to apply [rotor]"),
    ("observer.location", "IO91wm", "a running station applies it within seconds"),
    ("satellites.names", '{ 25544 = "ZARYA" }', "a running station applies it within seconds"),
    ("server.satellite", "7530", "used when the station starts; a running station keeps its current setting"),
])
def test_set_says_how_a_running_station_takes_the_change(station_file, capsys, key: str, value: str,
                                                         says: str) -> None:
    """#34 item 2: what needs a restart was said only in the station's log; ``config set`` says it itself."""
    capsys.readouterr()
    assert main(["config", "set", "--config", str(station_file), key, value]) == 0
    out = capsys.readouterr().out.strip()
    section, name = key.split(".")
    assert out == f"{station_file}: [{section}] {name} set; {says}"


@pytest.mark.parametrize(("content", "says"), [
    ("[tcp\n", "the file is not valid TOML, so it was not changed (Expected ']' at the end of a table declaration"),
    ("web = 1\n", "[web] is a plain value (web = ...) in the file, not a table; fix or remove it first"),
    ('[[web]]\ntoken = "x"\n', "[web] is an array of tables ([[web]]) in the file, not a table"),
    ("[web]\nenabled = false\n[web]\nport = 1\n", "the file is not valid TOML, so it was not changed (Cannot declare"),
])
def test_a_malformed_file_is_one_sentence_not_a_traceback(tmp_path, capsys, content: str, says: str) -> None:
    """#34 item 13: these four shapes made ``config set`` print a tomlkit traceback (TypeError, ParseError)."""
    path = tmp_path / "c.toml"
    path.write_text(content)
    assert main(["config", "set", "--config", str(path), "web.enabled", "true"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("nfwserver: web.enabled = True refused: ") and says in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert path.read_text() == content


def test_a_text_setting_takes_digits_as_text(station_file, capsys) -> None:
    """#34 item 13: ``web.token 73190286`` was read as the integer 73190286 and refused as no text."""
    assert main(["config", "set", "--config", str(station_file), "web.token", "7319028644109372"]) == 0
    assert load_config(station_file).web.token == "7319028644109372"
    assert main(["config", "set", "--config", str(station_file), "tcp.port", "9001"]) == 0  # numbers stay numbers
    assert load_config(station_file).tcp.port == 9001


@pytest.mark.skipif(os.name == "nt", reason="symbolic links and FIFOs")
def test_set_and_init_write_through_a_symlink(tmp_path, capsys) -> None:
    """#34 item 13: a symlinked configuration (kept in a dotfiles repository) was replaced by a regular file."""
    real = tmp_path / "dotfiles" / "nfw.toml"
    real.parent.mkdir()
    assert main(["config", "init", "--config", str(real), "--locator", "JO01ab"]) == 0
    link = tmp_path / "config.toml"
    link.symlink_to(real)
    assert main(["config", "set", "--config", str(link), "tcp.enabled", "true"]) == 0
    assert link.is_symlink() and load_config(real).tcp.enabled
    assert main(["config", "init", "--config", str(link), "--force", "--locator", "IO91wm"]) == 0
    assert link.is_symlink() and load_config(real).observer == parse_observer("IO91wm")


@pytest.mark.skipif(os.name == "nt", reason="FIFOs and /dev/null")
def test_init_force_refuses_anything_but_a_regular_file(tmp_path, capsys) -> None:
    """#34 item 13: ``init --force`` replaced a FIFO and a character device."""
    fifo = tmp_path / "fifo.toml"
    os.mkfifo(fifo)
    device = tmp_path / "device.toml"
    device.symlink_to("/dev/null")  # a character device, reached through a link (never written on failure)
    for path in (fifo, device):
        capsys.readouterr()
        assert main(["config", "init", "--config", str(path), "--force"]) == 1
        assert "is not a regular file; not replacing it" in capsys.readouterr().err
    assert stat.S_ISFIFO(os.stat(fifo).st_mode) and device.is_symlink()
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)


@pytest.mark.skipif(os.name == "nt", reason="POSIX permission bits")
def test_a_file_holding_the_web_token_is_private_and_show_masks_it(station_file, capsys) -> None:
    """#34 item 13: the file holding the token stayed 0644 (readable by every local user) and ``config show``
    printed the token."""
    station_file.chmod(0o644)
    token = "q7Rk2mZp9vXw"
    assert main(["config", "set", "--config", str(station_file), "web.token", token]) == 0
    assert stat.S_IMODE(station_file.stat().st_mode) == 0o600
    assert main(["config", "set", "--config", str(station_file), "tcp.enabled", "true"]) == 0
    assert stat.S_IMODE(station_file.stat().st_mode) == 0o600  # and stays so
    capsys.readouterr()
    assert main(["config", "show", "--config", str(station_file)]) == 0
    out = capsys.readouterr().out
    assert token not in out
    assert 'token = "********"  # hidden (the file holds it)' in out


def test_init_echoes_the_position_it_derived(tmp_path, capsys) -> None:
    """#34 item 10: ``config init --locator`` did not say where it put the station.  The oracle is the Maidenhead
    rule worked by hand: IN80do is field I,N (20 deg x 10 deg from 180 W, 90 S), square 8,0 (2 x 1 deg),
    subsquare d,o (5' x 2.5'), and the position is the subsquare's centre."""
    lon = -180 + 8 * 20 + 8 * 2 + 3 * 5 / 60 + 2.5 / 60
    lat = -90 + 13 * 10 + 0 * 1 + 14 * 2.5 / 60 + 1.25 / 60
    path = tmp_path / "c.toml"
    assert main(["config", "init", "--config", str(path), "--locator", "IN80do"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out == [str(path), f"observer: {lat:.4f} N, {-lon:.4f} W, 0 m (from IN80do)"]
