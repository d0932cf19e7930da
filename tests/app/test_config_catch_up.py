"""``ConfigWatcher.catch_up`` runs before every command the web page posts (a token change applies before
``config set`` returns).  A file that is changed but not valid is left to the watcher's thread; catch_up
reads and parses it once, not again at each post: the posts are anyone's to send."""

from __future__ import annotations

from pathlib import Path

import pytest

import nfwserver.config.loader as loader
from nfwserver.app.config_watcher import ConfigWatcher
from nfwserver.clock import VirtualClock
from tests.autotrack.test_runtime import START


def test_an_invalid_file_is_parsed_once_by_catch_up_however_many_posts(tmp_path: Path, monkeypatch) -> None:
    path = tmp_path / "station.toml"
    path.write_text("[server]\nsatellite = 25544\n")
    applied: list[int | None] = []
    watcher = ConfigWatcher(path, VirtualClock(START), lambda c: applied.append(c.server.satellite),
                            lambda why: None, interval_s=None)
    watcher.catch_up()
    assert applied == [25544]
    parsed = []
    real = loader.parse_config
    monkeypatch.setattr(loader, "parse_config", lambda *a, **k: parsed.append(1) or real(*a, **k))
    path.write_text("[server]\nsatellite = -1\n")  # refused by its check
    for _ in range(50):
        watcher.catch_up()
    assert applied == [25544] and len(parsed) == 1
    path.write_text("[server]\nsatellite = 27607\n")  # valid again: applied at the next post
    watcher.catch_up()
    assert applied == [25544, 27607]


@pytest.mark.parametrize("text", ["[server]\nsatellite = ", "[nosuchsection]\nx = 1\n"])
def test_each_new_state_of_the_file_is_looked_at_once(tmp_path: Path, monkeypatch, text: str) -> None:
    path = tmp_path / "station.toml"
    path.write_text("[server]\nsatellite = 25544\n")
    watcher = ConfigWatcher(path, VirtualClock(START), lambda c: None, lambda why: None, interval_s=None)
    watcher.catch_up()
    read = []
    real = loader.read_config_text
    monkeypatch.setattr(loader, "read_config_text", lambda p: read.append(1) or real(p))
    path.write_text(text)
    for _ in range(20):
        watcher.catch_up()
    assert len(read) == 1
