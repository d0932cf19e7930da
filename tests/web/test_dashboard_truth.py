"""What the page says must be true, in real headless Chromium: the log shown once, the live badge only while
frames come."""

from __future__ import annotations

from selenium.webdriver.common.by import By

from tests.web.conftest import config_text, open_page, start_station, wait_for


def test_a_connecting_page_shows_each_log_line_once(browser, web_station) -> None:
    """6ca6bee showed the recent log twice: the history, then the first frame's ``log``."""
    open_page(browser, web_station)  # the station's clock stands still: no event comes after the history
    rows = browser.execute_script(
        "return [...document.querySelectorAll('#logrows li')].map(li => [li.dataset.seq, li.textContent]);")
    events = web_station.station.core.events.recent(200)
    assert len(rows) == len(events), (len(rows), len(events))
    assert [int(seq) for seq, _ in rows] == [e.seq for e in events]
    web_station.advance(1.0)  # new events are added once each
    wait_for(lambda: browser.execute_script("return document.querySelectorAll('#logrows li').length")
             == len(web_station.station.core.events.recent(200)), 20.0, "the new lines, once each")


class _FailingRotor:
    """A rotor whose driver cannot be read (stands in for an adapter that raises while a frame is built)."""

    @property
    def driver(self) -> object:
        raise RuntimeError("rotor state unavailable")


def test_the_live_badge_says_when_frames_stop(browser, web_station) -> None:
    """6ca6bee left "live" on while every frame failed to build."""
    open_page(browser, web_station)
    badge = browser.find_element(By.CSS_SELECTOR, '[data-testid="connection"]')
    assert badge.text == "live"
    web = web_station.station.web
    assert web is not None
    web.parts.rotor = _FailingRotor()  # type: ignore[assignment]
    web_station.advance(0.6)
    wait_for(lambda: badge.text == "not updating", what="the badge to say frames stopped")
    assert "rotor state unavailable" in badge.get_attribute("title")
    web.parts.rotor = None
    web_station.advance(0.6)
    wait_for(lambda: badge.text == "live", what="live again after the first good frame")


def test_doppler_tuning_without_a_channel_is_not_shown_as_on(browser) -> None:
    """#34 item 8: a green "DOPPLER ON" stood beside "no radio channel for this satellite"."""
    web = start_station(config_text())  # ISS has a built-in channel; 694 (in visual.txt) has none
    try:
        web.station.core.set_doppler(True)
        open_page(browser, web)
        radio = browser.find_element(By.CSS_SELECTOR, '[data-testid="radio-state"]')
        wait_for(lambda: radio.text == "DOPPLER ON", what="DOPPLER ON for the ISS, which has a channel")
        assert "on" in radio.get_attribute("class").split()
        assert web.station.core.command("SAT=694", source="test").accepted
        web.advance(0.6)
        wait_for(lambda: radio.text == "DOPPLER IDLE: NO CHANNEL", what="the badge to say no channel")
        classes = radio.get_attribute("class").split()
        assert "warn" in classes and "on" not in classes
        doppler = browser.find_element(By.CSS_SELECTOR, '[data-testid="doppler"]')
        assert doppler.text == "no radio channel for this satellite"
    finally:
        web.station.stop()
