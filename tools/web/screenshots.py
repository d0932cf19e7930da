"""Take the dashboard screenshots in docs/ (phone 390x844 and desktop 1280x1000) in headless Chromium.

A station on a virtual clock during an ISS pass over Cambridge (the tests' data), with the simulated rotor
tracking and control on, exactly as tests/web starts it:

    PYTHONPATH=. python3 tools/web/screenshots.py docs
"""

from __future__ import annotations

import sys
from pathlib import Path

from selenium.webdriver.common.by import By

from tests.waiting import wait_for
from tests.web.conftest import config_text, make_browser, open_page, read_page, start_station


def main(target: str) -> None:
    text = config_text().replace("[web]", '[rotor]\nbackend = "sim"\nflip = "off"\n'
                                 '[horizon]\npoints = [[0, 5], [90, 12], [180, 3], [270, 8]]\n[web]') \
        .replace("tune = true", "tune = true\ntrack = true")
    web = start_station(text)
    try:
        web.station.core.command("TUNE ON", source="conv 1 on NFW32/NFW_DATA")
        web.advance(20.0)
        for name, width, height, mobile in (("web-phone.png", 390, 844, True), ("web-desktop.png", 1280, 1000, False)):
            browser = make_browser(width, height)
            try:
                browser.execute_cdp_cmd("Emulation.setDeviceMetricsOverride",
                                         {"width": width, "height": height, "deviceScaleFactor": 2 if mobile else 1,
                                          "mobile": mobile})
                frames = open_page(browser, web)["frames"]
                web.advance(1.0)
                # passes and map data arrive after the first frame: wait for the pass rows, the satellite's mark
                # and a frame after the advance
                wait_for(lambda b=browser, f=frames: b.find_elements(By.CSS_SELECTOR, "#passes tr[data-catalog-number]")
                         and (page := read_page(b))["frames"] > f and page["marker"] is not None,
                         15.0, "the pass list, the sky mark and the next frame")
                browser.save_screenshot(str(Path(target) / name))
            finally:
                browser.quit()
    finally:
        web.station.stop()


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "docs")
