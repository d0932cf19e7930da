"""The dashboard's pass list for a favourite above the horizon all day (issue 34, item 7), in real Chromium."""

from __future__ import annotations

from selenium.webdriver.common.by import By

from tests.web.conftest import console_errors, open_page, wait_for

METEOSAT_10 = 38552


def test_a_favourite_up_all_day_is_listed_as_up_for_the_whole_window(browser, tmp_path) -> None:
    from tests.conftest import DATA
    from tests.web.conftest import config_text, start_station

    meteosat = next(block for block in zip(*[iter((DATA / "active.txt").read_text().splitlines())] * 3)
                    if block[1].startswith(f"1 {METEOSAT_10}"))
    elements = tmp_path / "with_meteosat.txt"
    elements.write_text((DATA / "visual.txt").read_text() + "\n".join(meteosat) + "\n")
    web = start_station(config_text(elements, favourites=f"[25544, {METEOSAT_10}]"))
    try:
        assert wait_for(lambda: web.get("/api/passes")["version"] >= 1, what="the first pass search")
        entry = next(p for p in web.get("/api/passes")["passes"] if p["catalog_number"] == METEOSAT_10)
        assert entry["aos"] is None and entry["los"] is None and entry["max_el"] > 20.0
        open_page(browser, web)
        selector = f'#passes tr[data-catalog-number="{METEOSAT_10}"]'
        row = wait_for(lambda: browser.find_elements(By.CSS_SELECTOR, selector), what="METEOSAT-10's row")[0]
        assert "up for the whole window" in row.text and f"{entry['max_el']:.0f}\u00b0" in row.text
        assert console_errors(browser) == []
    finally:
        web.station.stop()
