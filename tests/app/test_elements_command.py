"""``nfwserver elements update`` over local HTTP and files: UPDATE semantics, summary, atomic store."""

from __future__ import annotations

import dataclasses
import os
from datetime import timedelta

import pytest

from nfwserver.app.element_store import ElementStore
from nfwserver.cli import main
from nfwserver.tracking.elements import ElementSet, load_element_file
from nfwserver.tracking.tle import parse_tle
from tests.app.test_station import http_server  # noqa: F401  (fixture)
from tests.conftest import DATA


def _newer(es: ElementSet, days: float) -> str:
    fields = dataclasses.replace(parse_tle(es.line1, es.line2), epoch=es.epoch + timedelta(days=days))
    return ElementSet.from_fields(es.name, fields).tle_text()


def test_update_from_http_and_a_file_then_only_newer_epochs(http_server, tmp_path, capsys) -> None:  # noqa: F811
    store = tmp_path / "store" / "elements.txt"
    junk = tmp_path / "junk.txt"
    junk.write_text("1 25544U bad line\nnothing else\n")
    assert main(["elements", "update", f"{http_server}/visual.txt", str(junk), "--store", str(store)]) == 0
    out, err = capsys.readouterr()
    assert "added 148, updated 0" in out and "rejected 1" in out and "rejected:" in err
    assert len(ElementStore(store).load()) == 148
    first = load_element_file(DATA / "visual.txt").sets[0]
    newer = tmp_path / "newer.txt"
    newer.write_text(_newer(first, 1.0) + _newer(load_element_file(DATA / "visual.txt").sets[1], -3.0))
    assert main(["elements", "update", str(newer), "--store", str(store)]) == 0
    assert "added 0, updated 1, not newer 1" in capsys.readouterr().out
    stored = {s.catalog_number: s for s in ElementStore(store).load()}
    assert stored[first.catalog_number].epoch == first.epoch + timedelta(days=1)
    assert main(["elements", "list", "--store", str(store)]) == 0
    assert "ISS" in capsys.readouterr().out


def test_failed_write_keeps_the_previous_store(tmp_path, monkeypatch, capsys) -> None:
    store = tmp_path / "elements.txt"
    assert main(["elements", "update", str(DATA / "visual.txt"), "--store", str(store)]) == 0
    before = store.read_bytes()
    first = load_element_file(DATA / "visual.txt").sets[0]
    newer = tmp_path / "newer.txt"
    newer.write_text(_newer(first, 2.0))

    def crash(src, dst):
        raise OSError("power cut")

    monkeypatch.setattr(os, "replace", crash)
    assert main(["elements", "update", str(newer), "--store", str(store)]) == 1
    assert "cannot write" in capsys.readouterr().err
    monkeypatch.undo()
    assert store.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["elements.txt", "newer.txt"]


def test_unreachable_url_is_reported(tmp_path, capsys) -> None:
    assert main(["elements", "update", "http://127.0.0.1:9/none.txt", "--store", str(tmp_path / "s.txt"),
                 "--timeout", "2"]) == 1
    assert "unavailable:" in capsys.readouterr().err


def test_without_sources_and_configuration(tmp_path, capsys) -> None:
    config = tmp_path / "c.toml"
    config.write_text("[elements]\nuse_bundled = true\n")
    assert main(["elements", "update", "--config", str(config), "--store", str(tmp_path / "s.txt")]) == 1
    assert "no sources" in capsys.readouterr().err


@pytest.mark.parametrize("text", ["[elements]\nstore = 5\n"])
def test_store_key_is_validated(text) -> None:
    from nfwserver.config import ConfigError, parse_config

    with pytest.raises(ConfigError, match=r"\[elements\] store"):
        parse_config(text)


def test_the_station_starts_from_the_stored_catalog(tmp_path) -> None:
    from nfwserver.app.station import Station
    from nfwserver.clock import SystemClock
    from nfwserver.config import parse_config
    from nfwserver.fake_dde import FakeDdeSystem

    store = tmp_path / "elements.txt"
    assert main(["elements", "update", str(DATA / "visual.txt"), "--store", str(store)]) == 0
    config = parse_config(f'[elements]\nuse_bundled = false\nstore = "{store}"\n')
    station = Station(config, SystemClock(), transport=FakeDdeSystem().server_transport())
    station.start()
    station.stop()
    assert len(station.catalog) == 148
