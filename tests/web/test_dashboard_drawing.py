"""The page finished for the eye, in real headless Chromium: long passes drawn whole, an always-up satellite,
labels clear of markers, ring labels, the sub-point's hemispheres, honest placeholders, the publish filter,
the pass list's columns and zones, and cards without large empty areas."""

from __future__ import annotations

import math
import re
import socket
from datetime import timedelta

from selenium.webdriver.common.by import By

from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.passes import find_passes
from tests.conftest import DATA
from tests.dde.conftest import DAY
from tests.web.conftest import config_text, make_browser, open_page, start_station, wait_for
from tests.web.test_dashboard_truth import _FailingRotor

CAMBRIDGE = Observer(52.2053, 0.1218, 20.0)  # config_text's observer
ROTOR = '[rotor]\nbackend = "sim"\nflip = "off"\n[web]'


def _elements(tmp_path, numbers: tuple[int, ...]):
    """A file with the named sets from the tests' whole catalog (AO-10 14129, METEOSAT-10 38552, ISS 25544)."""
    lines = (DATA / "active.txt").read_text().splitlines()
    keep = [lines[i:i + 3] for i in range(0, len(lines) - 2, 3) if int(lines[i + 1][2:7]) in numbers]
    path = tmp_path / "some.txt"
    path.write_text("\n".join(line for group in keep for line in group) + "\n")
    return path


DRAWN_TRACK = """
const xy = el => [Number(el.getAttribute('cx')), Number(el.getAttribute('cy'))];
const line = document.querySelector('#polar polyline.track');  // no points until the page has drawn a track
const poly = ((line && line.getAttribute('points')) || '').trim();
const points = poly ? poly.split(/\\s+/).map(p => p.split(',').map(Number)) : [];
const mark = k => { const el = document.querySelector(`[data-testid="pass-${k}"]`); return el ? xy(el) : null; };
const box = el => { const b = el.getBoundingClientRect(); return [b.left, b.top, b.right, b.bottom]; };
const labels = [...document.querySelectorAll('#polar .passlabel')].map(t => ({text: t.textContent, box: box(t)}));
const markers = [...document.querySelectorAll('#polar .passmark, [data-testid="sat-marker"]:not(.hidden)')]
  .map(box);
const all = [...document.querySelector('#polar').querySelectorAll('*')];
return {points, aos: mark('aos'), tca: mark('tca'), los: mark('los'), labels, markers,
        labels_above: labels.length === 0 || all.indexOf(document.querySelector('#polar .passlabel'))
          > all.indexOf(document.querySelector('[data-testid="sat-marker"]')),
        countdown: [document.querySelector('[data-testid="countdown-label"]').textContent,
                    document.querySelector('[data-testid="countdown"]').textContent]};
"""


def _overlap(a, b) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def test_a_nine_hour_pass_is_drawn_whole_with_its_labels_clear(browser, tmp_path) -> None:
    """6ca6bee drew AO-10's long pass as a stub (2000 points of 10 s), TCA and LOS floating unconnected."""
    elements = _elements(tmp_path, (14129, 25544))
    sets = {s.catalog_number: s for s in load_element_file(elements).sets}
    passes = find_passes([sets[14129]], CAMBRIDGE, DAY, DAY + timedelta(days=2))
    long = max((p for p in passes if p.aos and p.los), key=lambda p: p.los - p.aos)  # type: ignore[operator]
    assert long.duration_s is not None and long.duration_s > 9 * 3600
    web = start_station(config_text(elements, favourites="[14129]").replace("satellite = 25544", "satellite = 14129"),
                        start=long.aos + timedelta(minutes=40))
    try:
        open_page(browser, web)
        drawn = wait_for(lambda: (d := browser.execute_script(DRAWN_TRACK))["los"] and d["points"] and d,
                         what="AO-10's pass track")
        points = drawn["points"]
        assert math.dist(points[0], drawn["aos"]) < 1.0 and math.dist(points[-1], drawn["los"]) < 1.0, \
            (points[0], points[-1], drawn["aos"], drawn["los"])  # from AOS to LOS, whole
        assert min(math.dist(p, drawn["tca"]) for p in points) < 1.5  # TCA on the line
        assert max(math.dist(a, b) for a, b in zip(points, points[1:])) < 6.0  # no jump: one line
        assert sorted(label["text"] for label in drawn["labels"]) == ["AOS", "LOS", "TCA"]
        assert drawn["labels_above"]  # drawn after (over) the satellite marker
        for label in drawn["labels"]:
            assert not any(_overlap(label["box"], m) for m in drawn["markers"]), label
    finally:
        web.station.stop()


def test_a_satellite_up_all_day_is_a_point(browser, tmp_path) -> None:
    """6ca6bee drew nothing for METEOSAT-10 (35 degrees up all day at 40.4N 3.7W)."""
    elements = _elements(tmp_path, (38552, 25544))
    text = config_text(elements, favourites="[38552]").replace("satellite = 25544", "satellite = 38552") \
        .replace('location = "52.2053,0.1218,20"', 'location = "40.4,-3.7,650"')
    web = start_station(text)
    try:
        wait_for(lambda: (web.get("/api/passes")["track"] or {}).get("always_up"), what="always up")
        open_page(browser, web)
        drawn = wait_for(lambda: (d := browser.execute_script(DRAWN_TRACK))["tca"] and d, what="the point")
        assert drawn["points"] == [] and drawn["aos"] is None and drawn["los"] is None
        assert [label["text"] for label in drawn["labels"]] == ["up all day"]
        state = web.get("/api/state")["now"]["position"]
        track = web.get("/api/passes")["track"]
        assert abs(track["points"][0][0] - state["az"]) < 0.5 and abs(track["points"][0][1] - state["el"]) < 0.5
        assert 30 < state["el"] < 45
        wait_for(lambda: browser.execute_script(DRAWN_TRACK)["countdown"] == ["Up", "all day"], what="the countdown")
    finally:
        web.station.stop()


def test_rings_hemispheres_and_the_publish_filter(browser, web_station) -> None:
    open_page(browser, web_station)
    rings = browser.execute_script("return ['0', '30', '60'].map(e => "
                                   "(document.querySelector(`[data-testid='ring-${e}']`) || {}).textContent)")
    assert rings == ["0\u00b0", "30\u00b0", "60\u00b0"]
    sub = web_station.get("/api/state")["now"]["subpoint"]
    shown = browser.find_element(By.CSS_SELECTOR, '[data-testid="subpoint"]').text.replace("\n", " ")
    match = re.fullmatch(r"(\d+\.\d\d)°([NS]) (\d+\.\d\d)°([EW]) ([A-R]{2}\d\d[a-x]{2})", shown)
    assert match, shown
    assert match[2] == ("N" if sub["lat"] >= 0 else "S") and match[4] == ("E" if sub["lon"] >= 0 else "W")
    assert abs(float(match[1]) - abs(sub["lat"])) < 0.5 and abs(float(match[3]) - abs(sub["lon"])) < 0.5
    count = "return [...document.querySelectorAll('#logrows li[data-kind=publish]')].filter(li => !li.hidden).length"
    assert browser.execute_script("return document.querySelectorAll('#logrows li[data-kind=publish]').length") > 0
    assert browser.execute_script(count) == 0  # one a tick: off the page by default
    browser.find_element(By.CSS_SELECTOR, '[data-testid="log-publish"]').click()
    assert browser.execute_script(count) > 0
    browser.find_element(By.CSS_SELECTOR, '[data-testid="log-publish"]').click()


def test_placeholders_say_connecting_until_a_frame_comes(browser) -> None:
    """6ca6bee said "rotor: none configured" for a configured rotor until the first frame."""
    web = start_station(config_text().replace("[web]", ROTOR))
    try:
        assert web.station.web is not None
        web.station.web.parts.rotor = _FailingRotor()  # type: ignore[assignment]  # no frame can be built
        browser.get(web.url)
        wait_for(lambda: browser.execute_script("return document.body.dataset.ready"), what="the page's script")
        web.advance(0.4)
        for testid in ("rotor", "radio"):
            text = browser.find_element(By.CSS_SELECTOR, f'[data-testid="{testid}"]').text
            assert "connecting" in text and "none configured" not in text, text
    finally:
        web.station.stop()


def test_a_finished_poke_connection_leaves_the_clients() -> None:
    web = start_station(config_text().replace("[web]", "[tcp]\nenabled = true\nport = 0\n[web]"))
    try:
        tcp = web.station.tcp
        assert tcp is not None and tcp.address is not None
        with socket.create_connection(tcp.address[:2], timeout=10) as poke:  # as `nfwserver poke` does
            reader = poke.makefile("rb")
            reader.readline()  # greeting
            poke.sendall(b"TUNE ON\r\n")
            assert reader.readline().startswith(b"OK")
            peer = f"{poke.getsockname()[0]}:{poke.getsockname()[1]}"
            web.advance(0.4)
            wait_for(lambda: any(peer in c["name"] for c in web.get("/api/state")["clients"]["list"]),
                     what="the poke's connection among the clients")
            reader.close()  # the socket closes with its last file
        wait_for(lambda: web.station.core.events.recent(1)[-1].kind == "disconnect"
                 or any(e.kind == "disconnect" for e in web.station.core.events.recent(5)), what="the disconnect")
        web.advance(0.4)
        wait_for(lambda: not any(peer in c["name"] for c in web.get("/api/state")["clients"]["list"]),
                 what="the finished connection gone from Clients")
    finally:
        web.station.stop()


def test_the_pass_list_at_phone_width_and_in_a_utc_zone(web_station) -> None:
    phone = make_browser(390, 844)
    try:
        for zone, local_shown in (("UTC", False), ("Europe/Madrid", True)):
            phone.execute_cdp_cmd("Emulation.setTimezoneOverride", {"timezoneId": zone})
            open_page(phone, web_station)
            wait_for(lambda: phone.find_elements(By.CSS_SELECTOR, "#passes tr td"), what="the pass list")
            lines = phone.execute_script("""return [...document.querySelectorAll('#passes tr td:first-child')]
              .map(td => { const r = document.createRange(); r.selectNodeContents(td);
                return [td.textContent, new Set([...r.getClientRects()].map(x => Math.round(x.top))).size]; });""")
            assert lines and all(n == 1 for _, n in lines), lines  # the Sat column never wraps
            smalls = phone.execute_script("return [...document.querySelectorAll('#passes td small')]"
                                          ".map(s => s.textContent).filter(t => t)")
            assert bool(smalls) is local_shown, (zone, smalls[:3])
    finally:
        phone.quit()


def test_desktop_cards_have_no_large_empty_area(browser) -> None:
    """6ca6bee stretched the map card to the sky's height (about 200 px of nothing at 1280x900)."""
    web = start_station(config_text().replace("[web]", ROTOR))
    try:
        browser.set_window_size(1280, 900)
        open_page(browser, web)
        wait_for(lambda: browser.find_elements(By.CSS_SELECTOR, "#passes tr"), what="the pass list")
        empty = browser.execute_script("""return [...document.querySelectorAll('section.card')].map(card => {
            const last = [...card.children].filter(c => c.offsetParent !== null).pop();
            return [card.querySelector('h2').textContent,
                    Math.round(card.getBoundingClientRect().bottom - last.getBoundingClientRect().bottom)]; });""")
        assert all(gap < 40 for _, gap in empty), empty
    finally:
        web.station.stop()
