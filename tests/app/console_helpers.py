"""Helpers for driving the console with Textual's pilot: what is on screen, as text."""

from __future__ import annotations

import time

from textual.app import App
from textual.widgets import RichLog, Static

from tests.waiting import WaitTimeout


def screen_text(app: App) -> str:
    """Every character the terminal would show now, one line per row."""
    return "\n".join(strip.text for strip in app.screen._compositor.render_strips())


def log_text(app: App, pane: str) -> str:
    log = app.query_one(f"#{pane}", RichLog)
    return "\n".join(strip.text.rstrip() for strip in log.lines)


def off_screen(app: App) -> list[str]:
    """The widgets laid out beyond the terminal's edges.  The screen's text cannot tell: the compositor clips a
    300-column widget to an 80-column terminal, whose rows are then still 80 characters."""
    width, height = app.size
    return [f"{type(w).__name__}#{w.id} {w.region}" for w in app.screen.query("*")
            if w.display and (w.region.right > width or w.region.bottom > height)]


def static_text(app: App, widget_id: str) -> str:
    return str(app.query_one(f"#{widget_id}", Static).render())


async def settle(app: App, pilot, until=None, limit_s: float = 5.0, what: str = "", workers: bool = True) -> None:
    """Let worker threads (pass searches) finish and the screen catch up.  With ``until``, pause 0.05 s at a
    time until it holds, and fail (:class:`tests.waiting.WaitTimeout`) after ``limit_s`` seconds: a loaded
    machine cannot make the screen be read before its refresh, and a screen that never shows it cannot pass.
    Without ``until`` (nothing to wait for), pause 0.3 s.  ``workers=False``: do not wait for the workers
    (a test that holds one back)."""
    if workers:
        await app.workers.wait_for_complete()
    if until is None:
        await pilot.pause(0.3)
        return
    await pilot.pause()
    deadline = time.monotonic() + limit_s
    while not until():
        if time.monotonic() >= deadline:
            raise WaitTimeout(f"the console did not show {what or 'the awaited state'} within {limit_s:g} s")
        await pilot.pause(0.05)
