"""The dashboard's footer names the running program's version (#45 item 1), as ``nfwserver --version`` does."""

from __future__ import annotations

import html.parser
import io
import urllib.request
from contextlib import redirect_stdout

import pytest

from nfwserver.cli import main
from tests.web.conftest import config_text, start_station


class _Footer(html.parser.HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.inside = False
        self.text = ""

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.inside = self.inside or (tag == "footer" and ("data-testid", "version") in attrs)

    def handle_endtag(self, tag: str) -> None:
        if tag == "footer":
            self.inside = False

    def handle_data(self, data: str) -> None:
        if self.inside:
            self.text += data


def test_the_dashboards_footer_shows_the_version_the_command_shows() -> None:
    printed = io.StringIO()
    with redirect_stdout(printed), pytest.raises(SystemExit):
        main(["--version"])
    web = start_station(config_text(control=False))
    try:
        with urllib.request.urlopen(web.url, timeout=5) as page:
            footer = _Footer()
            footer.feed(page.read().decode("utf-8"))
    finally:
        web.station.stop()
    assert footer.text.strip() == printed.getvalue().strip()
