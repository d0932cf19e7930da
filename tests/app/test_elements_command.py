"""``nfwserver elements update``/``list`` over local HTTP and files: UPDATE semantics, the configured store."""

from __future__ import annotations

import dataclasses
import os
from datetime import timedelta

import pytest

from nfwserver.app.element_store import ElementStore
from nfwserver.cli import main
from nfwserver.tracking.elements import ElementSet, load_element_file
from nfwserver.tracking.tle import parse_tle
from tests.conftest import DATA


def _newer(es: ElementSet, days: float) -> str:
    fields = dataclasses.replace(parse_tle(es.line1, es.line2), epoch=es.epoch + timedelta(days=days))
    return ElementSet.from_fields(es.name, fields).tle_text()


def test_update_from_http_and_a_file_then_only_newer_epochs(http_server, tmp_path, capsys) -> None:  # noqa: F811
    store = tmp_path / "store" / "elements.txt"
    mixed = tmp_path / "mixed.txt"
    first, second = load_element_file(DATA / "visual.txt").sets[:2]
    mixed.write_text("1 25544U bad line\nnothing else\n" + first.tle_text())
    assert main(["elements", "update", f"{http_server}/visual.txt", str(mixed), "--store", str(store)]) == 0
    out, err = capsys.readouterr()
    assert not out.startswith("\n")
    assert "added 148, updated 0, not newer 1" in out and "rejected 1" in out and "rejected:" in err
    assert len(ElementStore(store).load()) == 148
    newer = tmp_path / "newer.txt"
    newer.write_text(_newer(first, 1.0) + _newer(second, -3.0))
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
    assert sorted(p.name for p in tmp_path.iterdir()) == [".elements.txt.lock", "elements.txt", "newer.txt"]


@pytest.mark.parametrize(("content", "says"), [
    (b"", "is empty"),
    (b"\n  \n", "is empty"),
    (b"<html><body>Not here</body></html>\n", "holds no element sets"),
    (bytes(range(256)) * 8, "binary data"),
    (b"\x89PNG\r\n\x1a\n" + b"\xff\xd8" * 300, "binary data"),
], ids=["empty", "blank", "html", "bytes", "png"])
def test_garbage_empty_or_binary_input_is_one_sentence_exit_1(tmp_path, capsys, content, says) -> None:
    bad = tmp_path / "keps.txt"
    bad.write_bytes(content)
    store = tmp_path / "s.txt"
    assert main(["elements", "update", str(bad), "--store", str(store)]) == 1
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and says in err and str(bad) in err
    assert not store.exists()


def test_http_failures_are_one_plain_sentence(http_server, tmp_path, capsys) -> None:  # noqa: F811
    store = ["--store", str(tmp_path / "s.txt"), "--timeout", "5"]
    assert main(["elements", "update", f"{http_server}/missing.txt", *store]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "HTTP 404" in err and "urlopen" not in err
    assert main(["elements", "update", "http://127.0.0.1:9/none.txt", *store]) == 1
    err = capsys.readouterr().err
    assert err == "nfwserver: cannot fetch http://127.0.0.1:9/none.txt: connection refused\n"


def test_unsupported_scheme_is_a_usage_error(tmp_path, capsys) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main(["elements", "update", "ftp://example.org/keps.txt", "--store", str(tmp_path / "s.txt")])
    assert exit_info.value.code == 2
    assert "unsupported scheme ftp://" in capsys.readouterr().err


def test_the_download_reports_progress_in_bytes(http_server) -> None:  # noqa: F811
    from nfwserver.app.element_sources import read_source

    seen: list[tuple[int, int | None]] = []
    loaded = read_source(f"{http_server}/active.txt", 10.0, lambda done, total: seen.append((done, total)))
    size = (DATA / "active.txt").stat().st_size
    assert len(loaded.sets) == 15347
    assert len(seen) > 10 and seen[-1] == (size, size)
    assert [d for d, _ in seen] == sorted({d for d, _ in seen})


def test_without_sources_and_configuration(tmp_path, capsys) -> None:
    config = tmp_path / "c.toml"
    """Nothing given, nothing configured: the default named source, said so (here offline: one line naming it)."""
    config.write_text('[elements]\nuse_bundled = true\npreset_mirror = "http://127.0.0.1:9"\n')
    assert main(["elements", "update", "--config", str(config), "--store", str(tmp_path / "s.txt")]) == 1
    err = capsys.readouterr().err.splitlines()
    assert err[0] == (f"nfwserver: no element sources configured ([elements] sources, files or urls in {config}): "
                      "using the amateur (CelesTrak, TLE) source")
    assert err[1].startswith("nfwserver: amateur (CelesTrak, TLE): cannot fetch "
                             "http://127.0.0.1:9/gp.php?GROUP=amateur&FORMAT=tle: ")
    assert len(err) == 2 and not (tmp_path / "s.txt").exists()


def test_update_and_list_follow_the_configured_store(tmp_path, capsys) -> None:
    config = tmp_path / "conf" / "c.toml"
    config.parent.mkdir()
    config.write_text('[elements]\nstore = "mine.txt"\nuse_bundled = false\n')
    assert main(["elements", "update", "--config", str(config), str(DATA / "visual.txt")]) == 0
    assert str(tmp_path / "conf" / "mine.txt") in capsys.readouterr().out
    assert len(ElementStore(tmp_path / "conf" / "mine.txt").load()) == 148
    from platformdirs import user_data_dir

    assert not (tmp_path.parent / user_data_dir("nfwserver")).exists()
    assert main(["elements", "list", "--config", str(config)]) == 0
    out, err = capsys.readouterr()
    lines = out.splitlines()
    assert len(lines) == 149 and all(" stored " in line for line in lines[1:])
    assert "bundled element set is in use" not in err

    from nfwserver.app.station_catalog import load_station_catalog
    from nfwserver.config.loader import load_config

    catalog, _ = load_station_catalog(load_config(config))
    assert {s.catalog_number for s in catalog} == {int(line.split()[0]) for line in lines[1:]}


def test_list_says_when_the_bundled_set_is_in_use(tmp_path, capsys) -> None:
    from nfwserver.radio.defaults import DEFAULT_CHANNELS

    config = tmp_path / "c.toml"
    config.write_text('[elements]\nstore = "none"\n')
    assert main(["elements", "list", "--config", str(config)]) == 0
    out, err = capsys.readouterr()
    assert "bundled element set is in use" in err
    rows = {int(line.split()[0]): line for line in out.splitlines()[1:]}
    assert set(DEFAULT_CHANNELS) <= set(rows) and all(" bundled " in line for line in rows.values())
    assert rows[43017].split()[1] == "AO-91"


def test_the_station_starts_from_the_stored_catalog(tmp_path) -> None:
    from nfwserver.app.station import Station
    from nfwserver.clock import SystemClock
    from nfwserver.config.loader import parse_config
    from nfwserver.fake_dde import FakeDdeSystem

    store = tmp_path / "elements.txt"
    assert main(["elements", "update", str(DATA / "visual.txt"), "--store", str(store)]) == 0
    config = parse_config(f'[elements]\nuse_bundled = false\nstore = "{store}"\n')
    station = Station(config, SystemClock(), transport=FakeDdeSystem().server_transport())
    station.start()
    station.stop()
    assert len(station.catalog) == 148
