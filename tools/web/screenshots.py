"""Take the dashboard screenshots in docs/ (phone 390x844 and desktop 1280x900) in headless Chromium.

A station on a virtual clock during an ISS pass over Cambridge (the tests' data), with the simulated rotor
tracking and control on, exactly as tests/web starts it:

    PYTHONPATH=. python3 tools/web/screenshots.py docs

and AO-10 during an 11-hour pass (``web-long-pass.png``, 1280x900).
"""

from __future__ import annotations

import sys
import tempfile
from datetime import timedelta
from pathlib import Path

from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.passes import find_passes
from tests.conftest import DATA
from tests.dde.conftest import DAY
from tests.web.conftest import WebStation, config_text, make_browser, open_page, start_station, wait_for

#: the page is drawn: the pass list, the map's land and the pass track are in
DRAWN = """return document.querySelectorAll('#passes tr').length > 0
  && (document.querySelector('#map path.land').getAttribute('d') || '').length > 1000
  && !!document.querySelector('[data-testid="pass-tca"]');"""


def shoot(web: WebStation, target: Path, shots: tuple[tuple[str, int, int, bool], ...]) -> None:
    """Each (file name, width, height, phone) of the running station's page, once it is drawn."""
    for name, width, height, mobile in shots:
        browser = make_browser(width, height)
        try:
            browser.execute_cdp_cmd("Emulation.setDeviceMetricsOverride",
                                     {"width": width, "height": height, "deviceScaleFactor": 2 if mobile else 1,
                                      "mobile": mobile})
            open_page(browser, web)
            web.advance(1.0)
            wait_for(lambda page=browser: page.execute_script(DRAWN), what="passes, map and pass track drawn")
            browser.save_screenshot(str(target / name))
        finally:
            browser.quit()


def long_pass(target: Path) -> None:
    """AO-10 40 minutes into an 11-hour pass over Cambridge: the whole pass drawn, labels clear."""
    lines = (DATA / "active.txt").read_text().splitlines()
    keep = [lines[i:i + 3] for i in range(0, len(lines) - 2, 3) if lines[i + 1][2:7] in ("14129", "25544")]
    with tempfile.TemporaryDirectory() as folder:
        elements = Path(folder) / "ao10.txt"
        elements.write_text("\n".join(line for group in keep for line in group) + "\n")
        ao10 = next(s for s in load_element_file(elements).sets if s.catalog_number == 14129)
        passes = find_passes([ao10], Observer(52.2053, 0.1218, 20.0), DAY, DAY + timedelta(days=2))
        longest = max((p for p in passes if p.aos and p.los), key=lambda p: p.duration_s or 0.0)
        assert longest.aos is not None
        text = config_text(elements, favourites="[14129, 25544]").replace("satellite = 25544", "satellite = 14129")
        web = start_station(text, start=longest.aos + timedelta(minutes=40))
        try:
            shoot(web, target, (("web-long-pass.png", 1280, 900, False),))
        finally:
            web.station.stop()


def main(target: str) -> None:
    text = config_text().replace("[web]", '[rotor]\nbackend = "sim"\nflip = "off"\n'
                                 '[horizon]\npoints = [[0, 5], [90, 12], [180, 3], [270, 8]]\n[web]') \
        .replace("tune = true", "tune = true\ntrack = true")
    web = start_station(text)
    try:
        web.station.core.command("TUNE ON", source="conv 1 on NFW32/NFW_DATA")
        web.advance(20.0)
        shoot(web, Path(target), (("web-phone.png", 390, 844, True), ("web-desktop.png", 1280, 900, False)))
    finally:
        web.station.stop()
    long_pass(Path(target))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "docs")
