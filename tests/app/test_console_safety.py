"""The console under hostile names, a rotctld reporting nan, a 15,000-object catalog and slow pass searches.

Names are shown literally (issue 18 item 4): markup in a satellite or DDE name is text, never style.
"""

from __future__ import annotations

import asyncio
import socket
import threading
from collections.abc import Iterator
from dataclasses import replace
from datetime import timedelta
from types import SimpleNamespace

import pytest

import nfwserver.console.app as console_app
from nfwserver.app.devices import make_rotor
from nfwserver.clock import SystemClock
from nfwserver.config.schema import RotorConfig
from nfwserver.console.app import NfwConsole
from nfwserver.console.picker import MAX_SHOWN, SatellitePicker
from nfwserver.rotor.coupling import RotorCoupling
from nfwserver.rotor.geometry import RotorGeometry
from nfwserver.rotor.kct_driver import KctDriver
from nfwserver.rotor.rotctld_backend import RotctldBackend
from nfwserver.tracking.catalog import Catalog
from nfwserver.tracking.elements import load_element_file
from tests.app.console_helpers import log_text, screen_text, searched, settle, static_text
from tests.conftest import DATA
from tests.dde.conftest import CATALOG, ISS, ISS_PASS, make_station

ACTIVE = DATA / "active.txt"  #: a CelesTrak snapshot of every active object (15,347 sets)


def _hostile_catalog() -> Catalog:
    sets = {s.catalog_number: s for s in load_element_file(DATA / "visual.txt").sets}
    sets[ISS] = replace(sets[ISS], name="[bold red]PWNED[/]")
    other = next(n for n in sorted(sets) if n != ISS)
    sets[other] = replace(sets[other], name="X [/bold] Y")
    return Catalog(sets.values(), dde_names={ISS: "[/b]"})


def test_markup_in_names_is_shown_literally_everywhere() -> None:
    station = make_station(start=ISS_PASS.tca, catalog=_hostile_catalog())

    async def scenario() -> None:
        app = NfwConsole(station.core, favourites=(ISS,))
        async with app.run_test(size=(120, 36)) as pilot:
            await settle(app, pilot, until=lambda: searched(app) and "PWNED" in static_text(app, "state"),
                         what="the hostile names and the pass search")
            state = static_text(app, "state")
            assert "Satellite [/b] (25544) [bold red]PWNED[/]" in state
            assert "[/b]" in static_text(app, "passes")
            await pilot.press("f2", *"PWNED")
            await pilot.pause()
            assert "[bold red]PWNED[/]" in screen_text(app)
            for _ in "PWNED":
                await pilot.press("backspace")
            await pilot.press(*"X [/bold]")
            await pilot.pause()
            assert "X [/bold] Y" in screen_text(app)
            await pilot.press("enter")
            await settle(app, pilot, until=lambda: station.core.state.catalog_number != ISS
                         and "X [/bold] Y" in static_text(app, "state"))
            other = station.core.state.catalog_number
            assert other != ISS and station.core.state.catalog.get(other).name == "X [/bold] Y"
            assert f"SAT={other} ok" in log_text(app, "incoming")
            assert "X [/bold] Y" in static_text(app, "state")

    asyncio.run(scenario())


@pytest.fixture
def nan_rotctld() -> Iterator[int]:
    """A loopback peer speaking rotctld's protocol that reports its position as nan."""
    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))
    listener.listen()
    listener.settimeout(0.1)
    stop = threading.Event()

    def serve() -> None:
        while not stop.is_set():
            try:
                conn, _ = listener.accept()
            except OSError:
                continue
            with conn:
                conn.settimeout(0.1)
                while not stop.is_set():
                    try:
                        data = conn.recv(1024)
                    except TimeoutError:
                        continue
                    if not data:
                        break
                    conn.sendall(b"nan\nnan\n" if data.startswith(b"p") else b"RPRT 0\n")

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    yield listener.getsockname()[1]
    stop.set()
    thread.join()
    listener.close()


def test_a_rotctld_reporting_nan_does_not_stop_the_console(nan_rotctld) -> None:
    station = make_station()
    geometry = RotorGeometry.preset("overlap-450")
    driver = KctDriver(SystemClock(), RotctldBackend(SystemClock(), geometry, port=nan_rotctld), geometry)
    driver.read_position()
    rotor = RotorCoupling(driver, lambda when: None, lambda when: None)

    async def scenario() -> None:
        app = NfwConsole(station.core, rotor=rotor)
        async with app.run_test(size=(120, 36)) as pilot:
            await settle(app, pilot, until=lambda: "Rotor:" in static_text(app, "state"))
            state = static_text(app, "state")
            assert state.startswith("Satellite ISS") and "Rotor:" in state
            await pilot.press(*"TUNE ON", "enter")
            await pilot.pause()
            assert "TUNE ON ok" in log_text(app, "incoming")  # still taking commands
        assert app.failure is None

    asyncio.run(scenario())


def test_rotor_flip_state_events_and_the_flip_commands() -> None:
    station = make_station()
    rotor = make_rotor(RotorConfig(backend="sim"), station.core, station.clock)
    station.core.rotor = rotor  # as the station sets it

    async def scenario() -> None:
        app = NfwConsole(station.core, rotor=rotor)
        async with app.run_test(size=(120, 36)) as pilot:
            await pilot.pause()
            assert "flip auto (normal)" in static_text(app, "state")
            await pilot.press("ctrl+f")
            await settle(app, pilot, until=lambda: "flip on (inverted)" in static_text(app, "state")
                         and "[rotor] flip mode on" in log_text(app, "incoming"))
            assert rotor.flip_mode == "on" and "flip on (inverted)" in static_text(app, "state")
            assert "[rotor] flip mode on" in log_text(app, "incoming")
            await pilot.press(*"FLIP OFF", "enter")
            await settle(app, pilot, until=lambda: "flip off (normal)" in static_text(app, "state"))
            assert rotor.flip_mode == "off" and "flip off (normal)" in static_text(app, "state")
            await pilot.press(*"FLIP SIDEWAYS", "enter")
            await settle(app, pilot, until=lambda: "FLIP needs" in log_text(app, "incoming"))
            assert rotor.flip_mode == "off"
            assert "FLIP needs AUTO, ON or OFF" in " ".join(log_text(app, "incoming").split())

    asyncio.run(scenario())


def test_tcp_clients_and_the_easycomm_line_are_shown_when_those_outputs_exist() -> None:
    station = make_station()
    tcp = SimpleNamespace(client_count=lambda: 3)
    easycomm = SimpleNamespace(last_line="AZ123.4 EL45.6 UP145800000 [/b]")

    async def scenario() -> None:
        app = NfwConsole(station.core, tcp=tcp, easycomm=easycomm)
        async with app.run_test(size=(120, 36)) as pilot:
            await pilot.pause()
            assert "TCP clients 3  EasyComm AZ123.4 EL45.6 UP145800000 [/b]" in static_text(app, "state")

    asyncio.run(scenario())


def test_picker_searches_15000_objects_preselects_and_closes_on_escape() -> None:
    catalog = Catalog(load_element_file(ACTIVE).sets)
    assert len(catalog) > 15000
    station = make_station(catalog=catalog)

    async def scenario() -> None:
        app = NfwConsole(station.core, favourites=(ISS,))
        async with app.run_test(size=(100, 30)) as pilot:
            await pilot.press("f2")
            await pilot.pause()
            picker = app.screen
            assert isinstance(picker, SatellitePicker)
            options = picker.query_one("#picker-list")
            assert options.option_count == MAX_SHOWN  # bounded, however large the catalog
            assert options.highlighted_option.id == str(ISS)  # the current satellite, preselected
            assert f"{len(catalog)} satellites" in screen_text(app)
            await pilot.press(*"STARLINK")
            await pilot.pause()
            assert options.option_count == MAX_SHOWN and "type more to narrow" in screen_text(app)
            assert all("STARLINK" in str(o.prompt) for o in options.options)
            for _ in "STARLINK":
                await pilot.press("backspace")
            await pilot.press(*"43017")
            await pilot.pause()
            assert options.highlighted_option.id == "43017"
            await pilot.press("escape")
            await pilot.pause()
            assert not isinstance(app.screen, SatellitePicker) and station.core.state.catalog_number == ISS
            await pilot.press("f2", *"43017", "enter")
            await settle(app, pilot, until=lambda: station.core.state.catalog_number == 43017)
            assert station.core.state.catalog_number == 43017

    asyncio.run(scenario())


def test_pass_searches_run_off_the_ui_thread(monkeypatch) -> None:
    release = threading.Event()
    threads = []
    real_search = console_app.search_passes

    def slow_search(*args):
        threads.append(threading.current_thread())
        release.wait(20)
        return real_search(*args)

    monkeypatch.setattr(console_app, "search_passes", slow_search)
    station = make_station(start=ISS_PASS.aos - timedelta(minutes=5))

    async def scenario() -> None:
        app = NfwConsole(station.core, favourites=(ISS,))
        async with app.run_test(size=(120, 36)) as pilot:
            await settle(app, pilot, until=lambda: threads and "searching..." in static_text(app, "passes"),
                         workers=False)
            assert threads and threads[0] is not threading.main_thread()
            assert "searching..." in static_text(app, "passes")
            await pilot.press(*"TUNE ON", "enter")  # keys are handled while the search is still running
            await pilot.pause()
            assert "TUNE ON ok" in log_text(app, "incoming") and not release.is_set()
            release.set()
            await settle(app, pilot, until=lambda: searched(app), what="the released pass search")
            assert "ISS" in static_text(app, "passes") and "Next pass " in static_text(app, "state")

    asyncio.run(scenario())

    assert CATALOG.get(ISS).name != "[bold red]PWNED[/]"  # the shared catalog was never touched
