"""Named element sources out of the box (#25 item 1): presets, `elements sources`, `elements update NAME`, the
station's periodic refresh, and an offline source that is one line while the store stays whole.

A real HTTP server on 127.0.0.1 (free port) answers CelesTrak's ``gp.php?GROUP=...&FORMAT=tle|json|csv`` and
AMSAT's ``nasabare.txt`` in each form, made from tests/data; ``[elements] preset_mirror`` points the presets at it.
"""

from __future__ import annotations

import http.server
import logging
import threading
import urllib.parse
from collections.abc import Iterator
from datetime import datetime, timezone

import pytest

from nfwserver.app.element_sources import read_source
from nfwserver.app.station import Station
from nfwserver.cli import main
from nfwserver.clock import VirtualClock
from nfwserver.config.element_presets import CELESTRAK_BASE, CELESTRAK_GROUPS, PRESETS, preset_urls
from nfwserver.config.loader import parse_config
from nfwserver.config.render import template
from nfwserver.fake_dde import FakeDdeSystem
from nfwserver.tracking.elements import load_element_file
from tests.app.element_formats import bare_tle, omm_csv, omm_json
from tests.conftest import DATA, advance_until

VISUAL = {s.catalog_number for s in load_element_file(DATA / "visual.txt").sets}


class Provider:
    """What the fake CelesTrak/AMSAT serves: every group is visual.txt in the asked-for form."""

    def __init__(self) -> None:
        self.source = DATA / "visual.txt"
        self.requests: list[str] = []

    def body(self, path: str) -> tuple[int, str]:
        url = urllib.parse.urlsplit(path)
        if url.path == "/nasabare.txt":
            return 200, bare_tle(self.source)
        query = dict(urllib.parse.parse_qsl(url.query))
        if url.path != "/gp.php" or query.get("GROUP") not in dict(CELESTRAK_GROUPS):
            return 404, "Not found"
        form = query.get("FORMAT")
        if form == "tle":
            return 200, self.source.read_text()
        if form == "json":
            return 200, omm_json(self.source)
        if form == "csv":
            return 200, omm_csv(self.source)
        return 400, "Invalid query"


@pytest.fixture
def provider() -> Iterator[tuple[str, Provider]]:
    state = Provider()

    class Handler(http.server.BaseHTTPRequestHandler):
        def do_GET(self) -> None:  # noqa: N802 - the http.server API
            state.requests.append(self.path)
            status, text = state.body(self.path)
            data = text.encode()
            self.send_response(status)
            self.send_header("Content-Length", str(len(data)))
            self.end_headers()
            self.wfile.write(data)

        def log_message(self, *args) -> None:
            pass

    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{server.server_address[1]}", state
    server.shutdown()
    server.server_close()


def test_presets_follow_the_providers_documented_urls() -> None:
    assert PRESETS["amateur"].url() == "https://celestrak.org/NORAD/elements/gp.php?GROUP=amateur&FORMAT=tle"
    assert PRESETS["weather-json"].url() == "https://celestrak.org/NORAD/elements/gp.php?GROUP=weather&FORMAT=json"
    assert PRESETS["active-csv"].url() == "https://celestrak.org/NORAD/elements/gp.php?GROUP=active&FORMAT=csv"
    assert PRESETS["amsat"].url() == "https://www.amsat.org/tle/current/nasabare.txt"
    assert PRESETS["stations"].url("http://m/x/") == "http://m/x/gp.php?GROUP=stations&FORMAT=tle"
    assert {"amateur", "stations", "weather", "active", "cubesat", "amsat"} <= set(PRESETS)
    assert CELESTRAK_BASE.startswith("https://")


def test_every_preset_is_read_in_its_own_form(provider) -> None:
    base, _ = provider
    for name in ("amateur", "stations-json", "weather-csv", "cubesat", "active-json", "amsat"):
        loaded = read_source(PRESETS[name].url(base))
        assert {s.catalog_number for s in loaded.sets} == VISUAL and not loaded.rejected, name


def test_elements_sources_lists_every_preset_and_marks_the_configured_ones(tmp_path, capsys) -> None:
    config = tmp_path / "c.toml"
    config.write_text('[elements]\nsources = ["amateur", "amsat"]\n')
    assert main(["elements", "sources", "--config", str(config)]) == 0
    out, err = capsys.readouterr()
    rows = out.splitlines()[1:]
    assert len(rows) == len(PRESETS)
    assert [r.split()[1] for r in rows if r.startswith("*")] == ["amateur", "amsat"]
    assert any(r.split()[0] == "weather-json" and r.endswith("gp.php?GROUP=weather&FORMAT=json") for r in rows)
    assert "in [elements] sources" in err and "(amateur, amsat)" in err


def test_update_by_preset_name_fills_the_store(tmp_path, capsys, provider) -> None:
    base, state = provider
    config = tmp_path / "c.toml"
    store = tmp_path / "store.txt"
    config.write_text(f'[elements]\npreset_mirror = "{base}"\nstore = "{store}"\n')
    assert main(["elements", "update", "amateur", "amsat", "weather-csv",
                 "--config", str(config)]) == 0
    out = capsys.readouterr().out
    assert "read from 3 of 3 source(s)" in out
    assert {s.catalog_number for s in load_element_file(store).sets} == VISUAL
    assert state.requests == ["/gp.php?GROUP=amateur&FORMAT=tle", "/nasabare.txt", "/gp.php?GROUP=weather&FORMAT=csv"]


def test_the_config_init_template_update_works_out_of_the_box(tmp_path, capsys, provider) -> None:
    """`config init`'s file names the amateur source, so a plain `elements update` fetches it."""
    base, state = provider
    config = tmp_path / "c.toml"
    config.write_text(template().replace("[elements]\n", f'[elements]\npreset_mirror = "{base}"\n', 1))
    assert main(["elements", "update", "--config", str(config), "--store", str(tmp_path / "s.txt")]) == 0
    assert state.requests == ["/gp.php?GROUP=amateur&FORMAT=tle"]


def test_offline_is_one_line_naming_the_source_and_the_store_stays(tmp_path, capsys, provider) -> None:
    base, _ = provider
    config = tmp_path / "c.toml"
    store = tmp_path / "store.txt"
    config.write_text(f'[elements]\nsources = ["amateur"]\npreset_mirror = "{base}"\nstore = "{store}"\n')
    assert main(["elements", "update", "--config", str(config)]) == 0
    before = store.read_bytes()
    capsys.readouterr()
    config.write_text(f'[elements]\nsources = ["amateur"]\npreset_mirror = "http://127.0.0.1:9"\nstore = "{store}"\n')
    assert main(["elements", "update", "--config", str(config)]) == 1
    out, err = capsys.readouterr()
    lines = err.splitlines()
    assert lines[0].startswith("nfwserver: amateur (CelesTrak, TLE): cannot fetch "
                               "http://127.0.0.1:9/gp.php?GROUP=amateur&FORMAT=tle: ")
    assert lines[1:] == [f"nfwserver: the stored catalog {store} is unchanged"] and out == ""
    assert store.read_bytes() == before


def test_the_running_station_refreshes_its_named_sources(tmp_path, provider, caplog) -> None:
    base, state = provider
    store = tmp_path / "store.txt"
    config = parse_config(f'[elements]\nsources = ["amateur-json"]\npreset_mirror = "{base}"\nstore = "{store}"\n'
                          "use_bundled = false\nrefresh_hours = 1\n")
    clock = VirtualClock(datetime(2026, 5, 8, tzinfo=timezone.utc))
    station = Station(config, clock, transport=FakeDdeSystem().server_transport())
    station.start()
    try:
        assert advance_until(clock, lambda: len(station.catalog) == len(VISUAL), limit_s=10)  # fetched after start
        assert state.requests == ["/gp.php?GROUP=amateur&FORMAT=json"]
        assert advance_until(clock, lambda: len(state.requests) == 2, step_s=20, limit_s=4000)  # an hour later
        station.config = parse_config(f'[elements]\nsources = ["amateur-json"]\npreset_mirror = "http://127.0.0.1:9"\n'
                                      f'store = "{store}"\nuse_bundled = false\n')  # the network is gone
        before = store.read_bytes()
        with caplog.at_level(logging.WARNING):
            station.refresh_elements()
        assert len(station.catalog) == len(VISUAL) and store.read_bytes() == before
    finally:
        station.stop()
    offline = [r.getMessage() for r in caplog.records if "amateur-json" in r.getMessage()]
    # One line, from the `elements` link (STATUS faults=elements while it lasts; #34 item 11).
    assert len(offline) == 1 and offline[0].startswith(
        "elements: amateur-json (CelesTrak, OMM JSON): cannot fetch http://127.0.0.1:9/gp.php")


def test_preset_urls_are_labelled_for_messages() -> None:
    assert preset_urls(["amsat"], "http://h") == {"http://h/nasabare.txt": "amsat (AMSAT, TLE)"}
