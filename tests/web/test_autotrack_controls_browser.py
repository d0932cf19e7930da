"""The dashboard's AUTO ON/OFF controls (issue 43 item 6) switch a running station's autotrack through the command
table, in headless Chromium; a satellite chosen on the page switches it off and the page says so."""

from __future__ import annotations

from selenium.webdriver.common.by import By

from tests.waiting import wait_for
from tests.web.conftest import TOKEN, config_text, open_page, start_station


def _click(browser, testid: str) -> None:
    browser.find_element(By.CSS_SELECTOR, f'[data-testid="{testid}"]').click()


def _reply(browser) -> str:
    return browser.find_element(By.CSS_SELECTOR, '[data-testid="control-reply"]').text


def test_auto_buttons_switch_autotrack_and_a_chosen_satellite_switches_it_off(browser) -> None:
    web = start_station(config_text())
    try:
        runtime = web.station.autotrack.runtime
        open_page(browser, web)
        token = browser.find_element(By.CSS_SELECTOR, '[data-testid="token"]')
        wait_for(lambda: token.is_enabled(), what="controls enabled")
        token.send_keys(TOKEN)
        assert not runtime.on
        _click(browser, "btn-auto-on")
        wait_for(lambda: runtime.on, what="AUTO ON to reach the station")
        box = browser.find_element(By.CSS_SELECTOR, '[data-testid="sat-input"]')
        box.send_keys("694")
        _click(browser, "btn-sat")
        wait_for(lambda: "autotrack switched off" in _reply(browser), what="the page to say autotrack is off")
        assert not runtime.on and web.station.core.state.catalog_number == 694
        _click(browser, "btn-auto-on")
        wait_for(lambda: runtime.on, what="AUTO ON again")
        _click(browser, "btn-auto-off")
        wait_for(lambda: not runtime.on, what="AUTO OFF")
    finally:
        web.station.stop()
