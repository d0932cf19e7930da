"""A command that reads single settings (``TrackingInputs.setting``) gets what the configuration holds: from the file
when there is one, else the table's defaults, which must be exactly what the built-in configuration holds."""

from __future__ import annotations

import argparse
from operator import attrgetter

import pytest

import nfwserver.config.files
import nfwserver.config.loader
from nfwserver.cli.tracking_options import TrackingInputs
from nfwserver.config.schema import Config
from nfwserver.config.table import SETTINGS


@pytest.fixture(autouse=True)
def user_file_here(tmp_path, monkeypatch) -> None:
    """The user's configuration file is one in ``tmp_path`` on every system (the XDG variables the suite sets
    move it on Linux only)."""
    path = tmp_path / "user" / "config.toml"
    for module in (nfwserver.config.files, nfwserver.config.loader):
        monkeypatch.setattr(module, "default_config_path", lambda: path)


@pytest.mark.parametrize("entry", [s for s in SETTINGS if s.where.split(".")[0] in Config.__dataclass_fields__],
                         ids=lambda s: s.name)
def test_without_a_file_each_setting_is_the_built_in_configurations(entry) -> None:
    assert not nfwserver.config.files.default_config_path().exists()
    inputs = TrackingInputs(argparse.Namespace(config=None))
    assert inputs.setting(entry.section, entry.key) == attrgetter(entry.where)(Config())
    # the configuration was built only for a key without a default (the observer's Greenwich, the flat horizon)
    assert (inputs._config is None) == (entry.default is not None)


def test_a_users_file_is_read_for_a_setting(tmp_path) -> None:
    path = nfwserver.config.files.default_config_path()
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


def test_no_file_is_decided_once_per_command(tmp_path) -> None:
    """A file that appears while a command runs does not mix its values with the defaults read before it."""
    inputs = TrackingInputs(argparse.Namespace(config=None))
    assert inputs.setting("elements", "stale_days") == 14.0
    path = nfwserver.config.files.default_config_path()
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("[elements]\nstale_days = 2\n")
    assert inputs.setting("elements", "stale_days") == 14.0
    assert inputs.config().elements.stale_days == 14.0
    assert TrackingInputs(argparse.Namespace(config=None)).setting("elements", "stale_days") == 2.0
