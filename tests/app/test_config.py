"""Configuration validation names the exact key; defaults work; atomic writes keep the old file."""

from __future__ import annotations

import os
import re
from dataclasses import replace

import pytest

from nfwserver.cli import main
from nfwserver.config.loader import ConfigError, load_config, parse_config
from nfwserver.config.render import template
from nfwserver.config.schema import DEFAULT_OBSERVER, Config
from nfwserver.config.tokens import TEMPLATE_TOKEN
from nfwserver.storage import atomic_write_text


def test_template_is_valid_and_means_the_defaults() -> None:
    config = parse_config(template())
    assert config.server.rate_hz == 5.0 and config.server.services == ("NFW32", "NFW_SERVER")
    assert config.observer == DEFAULT_OBSERVER and not config.observer_configured
    assert config.elements.use_bundled and config.elements.sources == ("amateur",)  # the starting source
    assert replace(config, source=Config().source, elements=replace(config.elements, sources=())) == Config()


def test_a_full_file(tmp_path) -> None:
    (tmp_path / "h.txt").write_text("0 5\n180 10\n")
    (tmp_path / "k.txt").write_text("")
    config = parse_config(
        '[observer]\nlocation = "QF56od"\n[horizon]\nfile = "h.txt"\n[elements]\nfiles = ["k.txt"]\n'
        '[server]\nrate_hz = 10\nsatellite = 27607\n[satellites]\nnames = { 25544 = "ARISS" }\nfavourites = [25544]\n',
        base_dir=tmp_path,
    )
    assert config.observer_configured and config.observer.latitude_deg < 0
    assert config.horizon.min_elevation(90) == pytest.approx(7.5)
    assert config.horizon_file == str(tmp_path / "h.txt")
    assert config.elements.files == (str(tmp_path / "k.txt"),)
    assert config.server.rate_hz == 10 and config.server.satellite == 27607
    assert config.dde_names == {25544: "ARISS"} and config.favourites == (25544,)
    assert config.warnings == ()


@pytest.mark.parametrize(
    ("text", "key"),
    [
        ("[server]\nrate_hz = 80\n", "[server] rate_hz: 80 is outside 1..50"),
        ("[server]\nrate_hz = 'fast'\n", "[server] rate_hz: must be a finite number"),
        ("[server]\nrate_hz = nan\n", "[server] rate_hz: must be a finite number"),
        ("[server]\nratehz = 5\n", "[server] ratehz: unknown key"),
        ("[server]\ntune = 'yes'\n", "[server] tune: must be true or false"),
        ("[server]\ntopic = ''\n", "[server] topic"),
        ("[observer]\nlocation = 'nowhere'\n", "[observer] location"),
        ("[observer]\nlatitude_deg = 95\nlongitude_deg = 0\n", "[observer] latitude_deg"),
        ("[observer]\nlatitude_deg = 52\n", "[observer] longitude_deg: required with latitude_deg"),
        ("[observer]\nlocation = 'JO02ae'\naltitude_m = 5\n", "[observer]: give location or altitude_m, not both"),
        ("[horizon]\npoints = [[0, 95]]\n", "[horizon] points"),
        ("[horizon]\npoints = [[0, 5]]\nfile = 'h.txt'\n", "[horizon]: give either points or file"),
        ("[horizon]\nfile = 'missing.txt'\n", "[horizon] file"),
        ("[elements]\nurls = ['ftp://x']\n", "[elements] urls: 'ftp://x' is not an http(s) URL"),
        ("[satellites]\nnames = { 25544 = 'TWO WORDS' }\n", "[satellites] names.25544"),
        ("[satellites]\nnames = { ISS = 'ISS' }\n", "[satellites] names.ISS: 'ISS' is not a catalog number"),
        ("[satellites]\nfavourites = [0]\n", "[satellites] favourites: 0 is not a catalog number"),
        ("[radio]\nstep_hz = 500\nknob_tolerance_hz = 100\n", "[radio] knob_tolerance_hz: 100 must be at least"),
        ("[rotor]\nflip = 'sometimes'\n", '[rotor] flip: must be one of "auto", "on", "off"'),
        ("[rotor]\npark_azimuth_deg = 360\n", "[rotor] park_azimuth_deg: 360 is outside 0..359"),
        ("[dialects]\ndde = ['nova']\n", '[dialects] dde: must be one of "orbitron", "wxtrack", "satpc32"'),
        ("[dialects]\ncallsign = 'A_VERY_LONG_CALL'\n", "[dialects] callsign: must be 1 to 12"),
        ("[antenna]\n", "[antenna]: unknown section"),
        ("observer = 5\n", "[observer]: must be a table"),
        ("this is not toml", "not valid TOML"),
    ],
)
def test_each_problem_names_its_key(text: str, key: str, tmp_path) -> None:
    with pytest.raises(ConfigError) as info:
        parse_config(text, "cfg.toml", tmp_path)
    assert key in str(info.value)


def test_all_problems_are_reported_together() -> None:
    with pytest.raises(ConfigError) as info:
        parse_config("[server]\nrate_hz = 80\nsatellite = -1\n[oops]\n")
    assert len(info.value.problems) == 3


def test_server_start_up_tune_and_track() -> None:
    assert (Config().server.tune, Config().server.track) == (False, False)  # as Nova: off until poked
    config = parse_config("[server]\ntune = true\ntrack = true\n")
    assert config.server.tune is True and config.server.track is True


@pytest.mark.parametrize("mode", ["auto", "on", "off"])
def test_rotor_flip_modes(mode) -> None:
    assert parse_config(f'[rotor]\nflip = "{mode}"\n').rotor.flip == mode


def test_missing_explicit_file_is_refused(tmp_path) -> None:
    with pytest.raises(ConfigError, match="cannot read the file: it does not exist"):
        load_config(tmp_path / "absent.toml")


def test_config_init_and_show(tmp_path, capsys) -> None:
    path = tmp_path / "sub" / "config.toml"
    assert main(["config", "init", "--config", str(path)]) == 0
    written = path.read_text()
    offered = re.search(r'^# token = "([^"]+)"$', written, re.MULTILINE)
    assert offered is not None and offered[1] != TEMPLATE_TOKEN  # a fresh token, not the example
    assert written == template().replace(f'# token = "{TEMPLATE_TOKEN}"', f'# token = "{offered[1]}"')
    assert main(["config", "init", "--config", str(path)]) == 1
    assert "already exists" in capsys.readouterr().err
    assert main(["config", "show", "--config", str(path)]) == 0
    out = capsys.readouterr().out
    assert f"# configuration: {path}" in out and "\nrate_hz = 5\n" in out
    path.write_text("[server]\nrate_hz = 0\n")
    assert main(["config", "show", "--config", str(path)]) == 1
    assert "[server] rate_hz" in capsys.readouterr().err


def test_atomic_write_keeps_the_old_file_when_writing_fails(tmp_path, monkeypatch) -> None:
    path = tmp_path / "catalog.txt"
    atomic_write_text(path, "old content")

    def broken_replace(src, dst):
        raise OSError("disk gone")

    monkeypatch.setattr(os, "replace", broken_replace)
    with pytest.raises(OSError):
        atomic_write_text(path, "new content")
    monkeypatch.undo()
    assert path.read_text() == "old content"
    assert [p.name for p in tmp_path.iterdir()] == ["catalog.txt"]  # no temporary file left behind
