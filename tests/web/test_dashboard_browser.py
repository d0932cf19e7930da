"""The dashboard in a real headless Chromium against a real station (tests/web/conftest.py)."""

from __future__ import annotations

import re
from datetime import timedelta

from selenium.common.exceptions import NoAlertPresentException
from selenium.webdriver.common.by import By

from tests.dde.conftest import NOVA
from tests.tracking.skyfield_oracle import TS, skyfield_satellite, skyfield_topos
from tests.waiting import wait_for
from tests.web.conftest import TOKEN, console_errors, open_page, read_page


def test_the_page_shows_the_published_nova_string_and_its_values(browser, web_station) -> None:
    open_page(browser, web_station)
    station = web_station.station
    published = station.core.current_text()
    # the clock stands still: the page settles on the string published now
    page = wait_for(lambda: (p := read_page(browser))["nova"] == published and p, what="the published string")
    match = NOVA.match(published)
    assert match, published
    name, az, el, rr, ah = match.groups()
    # Values shown agree with the Nova string's own fields (one decimal for AZ/EL as Nova prints them).
    assert (page["name"], page["az"], page["el"], page["ah"]) == (name, az, el, f"AH {ah}")
    assert abs(float(page["rr"]) - float(rr)) < 5e-5
    assert page["number"] == "(25544)" and page["full"] == "ISS (ZARYA)"
    assert (page["tune"], page["track"]) == ("TUNE ON", "TRACK OFF")
    # ... and with /api/state, read at the same instant.
    state = web_station.get("/api/state")
    assert state["now"]["nova"] == published
    assert page["az"] == f"{state['now']['position']['az']:.1f}"
    assert page["range"] == f"{state['now']['position']['range_km']:.1f}"
    assert page["status"] == state["now"]["status"]["hex"] == f"0x{station.core.tracker.status_word():04X}"
    # the pass in progress: the LOS countdown is the time to the set Skyfield finds (0 deg, no horizon table
    # here) from the station's clock, to the second the page shows plus the pass search's tolerance
    # (the pass board computes on its own thread: under load the first frames come before it has the pass)
    page = wait_for(lambda: (p := read_page(browser))["countdown_label"] == "LOS in" and p, what="the LOS countdown")
    assert re.fullmatch(r"\d+:\d\d", page["countdown"])
    minutes, seconds = page["countdown"].split(":")
    now = station.clock.now()
    iss = station.core.state.catalog.get(25544).elements
    when, kinds = skyfield_satellite(iss).find_events(skyfield_topos(station.core.state.observer),
                                                      TS.from_datetime(now), TS.from_datetime(now + timedelta(hours=1)),
                                                      altitude_degrees=0.0)
    los = next(t.utc_datetime() for t, kind in zip(when, kinds) if kind == 2)
    assert abs(int(minutes) * 60 + int(seconds) - (los - now).total_seconds()) <= 2.0, (page["countdown"], los, now)
    assert console_errors(browser) == []


def test_the_satellite_marker_moves_with_the_station_clock(browser, web_station) -> None:
    first = open_page(browser, web_station)["marker"]
    assert first is not None and not first["hidden"]
    web_station.advance(30.0)
    second = wait_for(lambda: (m := read_page(browser)["marker"])["cx"] != first["cx"] and m, what="the marker to move")
    la = web_station.station.core.tracker.last_sample.look_angles
    assert abs(float(second["az"]) - la.azimuth_deg) < 2.0 and abs(float(second["el"]) - la.elevation_deg) < 2.0
    assert (float(second["cx"]), float(second["cy"])) != (float(first["cx"]), float(first["cy"]))
    assert browser.find_element(By.CSS_SELECTOR, '[data-testid="polar"] [data-testid="pass-tca"]')


def _click(browser, testid: str) -> None:
    browser.find_element(By.CSS_SELECTOR, f'[data-testid="{testid}"]').click()


def _reply(browser) -> str:
    return browser.find_element(By.CSS_SELECTOR, '[data-testid="control-reply"]').text


def test_controls_change_the_station_with_the_token_and_are_refused_without(browser, web_station) -> None:
    open_page(browser, web_station)
    core = web_station.station.core
    token = browser.find_element(By.CSS_SELECTOR, '[data-testid="token"]')
    wait_for(lambda: token.is_enabled(), what="controls enabled")
    token.clear()
    _click(browser, "btn-track-on")
    wait_for(lambda: "refused" in _reply(browser), what="a refusal")
    assert "token" in _reply(browser) and not core.state.snapshot().tracking
    token.send_keys(TOKEN)
    _click(browser, "btn-track-on")
    wait_for(lambda: core.state.snapshot().tracking, what="TRACK ON to reach the station")
    web_station.advance(0.4)
    wait_for(lambda: read_page(browser)["track"] == "TRACK ON", what="the page to show TRACK ON")
    _click(browser, "btn-tune-off")
    wait_for(lambda: not core.state.snapshot().feed_on, what="TUNE OFF")
    # a refused command: the station's own refusal is shown, nothing changes
    box = browser.find_element(By.CSS_SELECTOR, '[data-testid="sat-input"]')
    box.send_keys("99999")
    _click(browser, "btn-sat")
    wait_for(lambda: "not in the catalog" in _reply(browser), what="the station's refusal")
    assert core.state.catalog_number == 25544
    # clicking a pass of another satellite selects it
    row = wait_for(lambda: [r for r in browser.find_elements(By.CSS_SELECTOR, "#passes tr[data-catalog-number]")
                            if r.get_attribute("data-catalog-number") != "25544"], what="another satellite's pass")[0]
    wanted = int(row.get_attribute("data-catalog-number"))
    row.click()
    wait_for(lambda: core.state.catalog_number == wanted, what="the satellite to change")
    sources = {e.client for e in core.events.recent() if e.kind == "poke" and e.accepted}
    assert any(s.startswith("web 127.0.0.1") for s in sources)


def test_hostile_names_and_strings_render_as_text(browser, tmp_path) -> None:
    from tests.conftest import DATA
    from tests.web.conftest import config_text, start_station

    hostile = "<img src=x onerror=alert(1)>"
    lines = (DATA / "visual.txt").read_text().splitlines()
    at = next(i for i, line in enumerate(lines) if line.startswith("1 25544U"))
    elements = tmp_path / "hostile.txt"
    elements.write_text(f"{hostile}\n{lines[at]}\n{lines[at + 1]}\n")
    web = start_station(config_text(elements, favourites="[25544]"))
    try:
        web.station.core.command(f"SAT={hostile}", source="<script>alert(2)</script>")
        web.advance(0.6)
        open_page(browser, web)
        page = read_page(browser)
        assert page["full"] == hostile
        log = browser.find_element(By.CSS_SELECTOR, '[data-testid="log"]').text
        assert hostile in log and "<script>alert(2)</script>" in log
        assert browser.find_elements(By.CSS_SELECTOR, "main img, main script") == []
        try:
            browser.switch_to.alert.dismiss()
            raise AssertionError("an alert ran")
        except NoAlertPresentException:
            pass
        assert console_errors(browser) == []
    finally:
        web.station.stop()


def test_controls_are_disabled_and_refused_when_control_is_off(browser) -> None:
    from tests.web.conftest import config_text, start_station

    web = start_station(config_text(control=False))
    try:
        open_page(browser, web)
        button = browser.find_element(By.CSS_SELECTOR, '[data-testid="btn-track-on"]')
        assert not button.is_enabled()
        assert "control is off" in browser.find_element(By.CSS_SELECTOR, '[data-testid="control-note"]').text
        status, body = web.post({"command": "TRACK ON", "token": "anything"})
        assert status == 403 and not body["ok"] and not web.station.core.state.snapshot().tracking
    finally:
        web.station.stop()


def test_the_page_fits_a_phone(web_station) -> None:
    from tests.web.conftest import make_browser

    phone = make_browser(390, 844)
    try:
        open_page(phone, web_station)
        width = phone.execute_script("return [document.documentElement.scrollWidth, window.innerWidth]")
        assert width[0] <= width[1], width  # no sideways scrolling
        for testid in ("now-tracking", "polar", "next-passes", "map", "clients", "log", "controls"):
            box = phone.find_element(By.CSS_SELECTOR, f'[data-testid="{testid}"]').rect
            assert box["width"] <= width[1] and box["x"] >= 0, (testid, box)
        assert console_errors(phone) == []
    finally:
        phone.quit()


def test_the_rotor_commanded_and_actual_positions_are_drawn_apart(browser) -> None:
    from nfwserver.rotor.coupling import sky_from_rotor
    from tests.web.conftest import config_text, start_station

    web = start_station(config_text(extra="").replace("[web]", '[rotor]\nbackend = "sim"\nflip = "off"\n[web]')
                        .replace("tune = true", "tune = true\ntrack = true"))
    try:
        rotor = web.station.rotor
        assert rotor is not None
        open_page(browser, web)

        def markers() -> dict:
            return browser.execute_script("""
                const get = id => { const el = document.querySelector(`[data-testid="${id}"]`);
                  return {hidden: el.classList.contains("hidden"), az: el.getAttribute("data-az"),
                          el: el.getAttribute("data-el"), tag: el.tagName}; };
                return {target: get("rotor-target"), actual: get("rotor-actual"),
                        text: document.querySelector('[data-testid="rotor"]').textContent};""")

        web.advance(2.0)
        shown = wait_for(lambda: (m := markers())["target"]["az"] is not None and m["actual"]["az"] is not None
                         and not m["target"]["hidden"] and m, what="both rotor marks")
        assert shown["target"]["tag"] != shown["actual"]["tag"]  # distinct marks
        assert shown["text"].startswith("rotor ok: commanded")
        web.advance(1.0)

        def near_rotor() -> bool:  # the rotor turns at 6 deg/s: within one tick (0.2 s) of the last frame
            az, el = sky_from_rotor(*rotor.driver.rotor_position())
            m = markers()["actual"]
            return abs(float(m["az"]) - az) < 2.5 and abs(float(m["el"]) - el) < 2.5

        wait_for(near_rotor, what="the actual mark at the rotor's position")
    finally:
        web.station.stop()


def test_a_favourite_whose_position_cannot_be_computed_is_named_under_the_passes(browser, tmp_path) -> None:
    """A favourite SGP4 refuses now (ISS's elements dated ten years back: decayed) is left out of the search
    and named under the pass list, as text, instead of vanishing from it."""
    from tests.conftest import DATA
    from tests.dde.conftest import dead_iss_text
    from tests.web.conftest import config_text, start_station

    elements = tmp_path / "with_dead.txt"
    elements.write_text((DATA / "visual.txt").read_text() + dead_iss_text())
    web = start_station(config_text(elements, favourites="[25544, 99901]"))
    try:
        assert wait_for(lambda: web.get("/api/passes")["version"] >= 1, what="the first pass search")
        assert web.get("/api/passes")["left_out"] == ["DEAD"]
        open_page(browser, web)
        note = wait_for(lambda: browser.find_element(By.CSS_SELECTOR, '[data-testid="left-out"]').text,
                        what="the left-out note")
        assert note == "Left out, position cannot be computed now: DEAD"
        rows = browser.find_elements(By.CSS_SELECTOR, "#passes tr")
        assert rows and all("DEAD" not in r.text for r in rows)
        assert console_errors(browser) == []
    finally:
        web.station.stop()


def test_no_left_out_note_when_every_favourite_is_computed(browser, web_station) -> None:
    open_page(browser, web_station)
    wait_for(lambda: browser.find_elements(By.CSS_SELECTOR, "#passes tr"), what="the pass list")
    note = browser.find_element(By.CSS_SELECTOR, '[data-testid="left-out"]')
    assert not note.is_displayed() and note.text == ""
