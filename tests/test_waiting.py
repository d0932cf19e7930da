"""The tests' waits fail when what they wait for never comes (issue 36 item 10), and their screen checks see what
the screen text hides (item 12)."""

from __future__ import annotations

import asyncio
import threading

import pytest
from textual.app import App

from tests.app.console_helpers import settle
from tests.waiting import WaitTimeout, wait_for


def test_wait_for_returns_what_it_waited_for() -> None:
    box: list[str] = []
    threading.Timer(0.05, box.append, ("done",)).start()
    assert wait_for(lambda: box and box[0], 5.0, "the timer") == "done"


def test_wait_for_fails_naming_what_never_came() -> None:
    with pytest.raises(WaitTimeout, match="waiting for the impossible"):
        wait_for(lambda: False, 0.1, "the impossible")
    with pytest.raises(WaitTimeout, match="state 3"):
        wait_for(lambda: None, 0.1, lambda: "state 3")


def test_wait_for_tolerates_only_what_it_is_told_to() -> None:
    def refuse() -> bool:
        raise ConnectionRefusedError

    with pytest.raises(WaitTimeout):
        wait_for(refuse, 0.1, tolerate=(OSError,))
    with pytest.raises(ConnectionRefusedError):
        wait_for(refuse, 0.1)


def test_settle_fails_when_the_screen_never_shows_it() -> None:
    async def scenario() -> None:
        app: App[None] = App()
        async with app.run_test() as pilot:
            await settle(app, pilot, until=lambda: True)  # at once
            with pytest.raises(WaitTimeout):
                await settle(app, pilot, until=lambda: False, limit_s=0.2)

    asyncio.run(scenario())


def test_off_screen_sees_a_widget_the_screen_text_hides() -> None:
    """A 300-column widget on an 80-column terminal: every row of the screen's text is still 80 characters
    (so a row-length check cannot fail); the widget's region shows it."""
    from textual.app import ComposeResult
    from textual.widgets import Static

    from tests.app.console_helpers import off_screen, screen_text

    class Wide(App[None]):
        CSS = "#wide { width: 300; }"

        def compose(self) -> ComposeResult:
            yield Static("x" * 300, id="wide")

    async def scenario() -> None:
        app = Wide()
        async with app.run_test(size=(80, 24)) as pilot:
            await pilot.pause()
            assert all(len(row) <= 80 for row in screen_text(app).splitlines())
            assert off_screen(app) == ["Static#wide Region(x=0, y=0, width=300, height=1)"]

    asyncio.run(scenario())


def test_settle_has_no_pause_without_a_condition_and_names_what_it_awaited() -> None:
    """Every console wait names its condition (there is no fixed-pause form), and its failure says which."""
    import inspect

    from tests.app.console_helpers import spin_until

    assert inspect.signature(settle).parameters["until"].default is inspect.Parameter.empty

    async def scenario() -> None:
        app: App[None] = App()
        async with app.run_test() as pilot:
            with pytest.raises(WaitTimeout, match="after 0.2 s waiting for the console to show the footer"):
                await settle(app, pilot, until=lambda: False, limit_s=0.2, what="the footer")
            with pytest.raises(WaitTimeout, match="after 0.1 s waiting for the console to reach the search"):
                await spin_until(lambda: False, 0.1, "the search")

    asyncio.run(scenario())
