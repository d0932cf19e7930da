"""``[autotrack]`` in the one configuration table: defaults, checks, ``config set`` and the satellites' default."""

from __future__ import annotations

import pytest

from nfwserver.cli import main
from nfwserver.config import ConfigError, parse_config
from nfwserver.config.schema import Config


def test_defaults_are_those_of_the_issue() -> None:
    config = Config()
    assert (config.autotrack.enabled, config.autotrack.min_el_deg, config.autotrack.min_gap_s) == (False, 10, 60)
    assert config.autotrack.satellites is None and config.autotrack_satellites() == ()
    favourites = parse_config("[satellites]\nfavourites = [27607, 25544]\n")
    assert favourites.autotrack_satellites() == (27607, 25544)  # the favourites, in their order


def test_satellites_are_numbers_or_names_in_priority_order() -> None:
    config = parse_config('[satellites]\nfavourites = [7530]\n[autotrack]\nenabled = true\n'
                          'satellites = ["SO-50", 25544, " AO-91 "]\nmin_el_deg = 20\nmin_gap_s = 120\n')
    assert config.autotrack_satellites() == ("SO-50", 25544, "AO-91")
    assert config.autotrack.enabled and config.autotrack.min_el_deg == 20 and config.autotrack.min_gap_s == 120


@pytest.mark.parametrize(("text", "problem"), [
    ("satellites = 25544", "[autotrack] satellites: must be a list of catalog numbers or names"),
    ('satellites = [25544, "so-50", "SO-50"]', '[autotrack] satellites: "SO-50" is listed twice'),
    ("satellites = [0]", "[autotrack] satellites: 0 is not a catalog number"),
    ('satellites = [""]', "[autotrack] satellites: must be a catalog number or a satellite's name"),
    ("min_el_deg = 91", "[autotrack] min_el_deg: 91 is outside 0..90"),
    ("min_gap_s = -1", "[autotrack] min_gap_s: -1 is outside 0..3600"),
    ("enabled = 1", "[autotrack] enabled: must be true or false"),
    ("min_gap = 60", "[autotrack] min_gap: unknown key (did you mean min_gap_s?"),
])
def test_bad_values_are_refused_naming_the_key(text: str, problem: str) -> None:
    with pytest.raises(ConfigError) as caught:
        parse_config(f"[autotrack]\n{text}\n")
    assert any(p.startswith(problem) for p in caught.value.problems), caught.value.problems


def test_too_many_satellites_are_refused() -> None:
    with pytest.raises(ConfigError, match="lists 1001 satellites, more than 1000"):
        parse_config(f"[autotrack]\nsatellites = [{', '.join(str(n) for n in range(1, 1002))}]\n")


def test_config_set_and_show(tmp_path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "c.toml"
    path.write_text("# mine\n", encoding="utf-8")
    assert main(["config", "set", "--config", str(path), "autotrack.enabled", "true"]) == 0
    assert main(["config", "set", "--config", str(path), "autotrack.satellites", '[25544, "SO-50"]']) == 0
    assert main(["config", "set", "--config", str(path), "autotrack.min_el_deg", "95"]) == 1
    assert "[autotrack] min_el_deg: 95 is outside 0..90" in capsys.readouterr().err
    config = parse_config(path.read_text(encoding="utf-8"))
    assert config.autotrack.enabled and config.autotrack_satellites() == (25544, "SO-50")
    assert main(["config", "show", "--config", str(path)]) == 0
    shown = capsys.readouterr().out
    part = shown[shown.index("[autotrack]"):].split("\n\n")[0].splitlines()
    assert part == ["[autotrack]", "enabled = true", 'satellites = [25544, "SO-50"]', "min_el_deg = 10",
                    "min_gap_s = 60"]
