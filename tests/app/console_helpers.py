"""Helpers for driving the console with Textual's pilot: what is on screen, as text."""

from __future__ import annotations

from collections.abc import Callable

from textual.app import App
from textual.widgets import RichLog, Static

from tests.waiting import wait_for_async


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


async def spin_until(until: Callable[[], object], limit_s: float, what: str) -> None:
    """Yield to the event loop 0.01 s at a time until ``until`` holds, without waiting for the screen to go idle
    (as :func:`settle` does, which a busy worker thread can hold up); fail after ``limit_s`` seconds."""
    await wait_for_async(until, limit_s, f"the console to reach {what}")


def searched(app: App) -> bool:
    """The first pass search has been drawn: the pass list and the state pane's next pass are no longer
    "searching..." (a console without an observer never searches, and never gets here)."""
    return ("searching..." not in static_text(app, "passes") and "Next pass: searching" not in static_text(app, "state")
            and static_text(app, "passes").strip() != "")


async def settle(app: App, pilot, until: Callable[[], object], limit_s: float = 5.0, what: str = "",
                 workers: bool = True) -> None:
    """Let worker threads (pass searches) finish, then let the screen catch up until ``until`` holds, pausing
    0.05 s at a time; fail (:class:`tests.waiting.WaitTimeout`) after ``limit_s`` seconds.  A loaded machine
    cannot make the screen be read before its refresh, and a screen that never shows it cannot pass; there is
    no "pause a while" form, since every test waits for something it can name.  ``workers=False``: do not wait
    for the workers (a test that holds one back)."""
    if workers:
        await app.workers.wait_for_complete()
    await pilot.pause()
    await wait_for_async(until, limit_s, f"the console to show {what or 'the awaited state'}", interval_s=0.05,
                         pause=pilot.pause)
