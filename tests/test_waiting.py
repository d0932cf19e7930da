"""The tests' waits fail when what they wait for never comes (issue 36 item 10)."""

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
