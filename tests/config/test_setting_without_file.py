"""A command that reads single settings (``TrackingInputs.setting``) gets what the configuration holds: from the file
when there is one, else the table's defaults, which must be exactly what the built-in configuration holds."""

from __future__ import annotations

import argparse
from typing import Any

import pytest

from nfwserver.cli.tracking_options import TrackingInputs
from nfwserver.config import Config, default_config_path
from nfwserver.config.table import SETTINGS


def _at(config: Config, where: str) -> Any:
    value: Any = config
    for name in where.split("."):
        value = getattr(value, name)
    return value


@pytest.mark.parametrize("entry", [s for s in SETTINGS if s.where.split(".")[0] in Config.__dataclass_fields__],
                         ids=lambda s: s.name)
def test_without_a_file_each_setting_is_the_built_in_configurations(entry) -> None:
    assert not default_config_path().exists()
    inputs = TrackingInputs(argparse.Namespace(config=None))
    assert inputs.setting(entry.section, entry.key) == _at(Config(), entry.where)
    # the configuration was built only for a key without a default (the observer's Greenwich, the flat horizon)
    assert (inputs._config is None) == (entry.default is not None)


def test_a_users_file_is_read_for_a_setting(tmp_path) -> None:
    path = default_config_path()
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text('[elements]\nstale_days = 3.5\n[satellites]\nnames = { "25544" = "ZARYA" }\n')
    inputs = TrackingInputs(argparse.Namespace(config=None))
    assert inputs.setting("elements", "stale_days") == 3.5
    assert inputs.setting("satellites", "names") == {25544: "ZARYA"}
    assert inputs.setting("server", "ut1_utc_s") == 0.0  # a key the file leaves out: the default


def test_an_explicit_file_is_read_even_when_the_user_has_none(tmp_path) -> None:
    path = tmp_path / "other.toml"
    path.write_text("[server]\nut1_utc_s = -0.25\n")
    assert TrackingInputs(argparse.Namespace(config=str(path))).setting("server", "ut1_utc_s") == -0.25
