"""Helpers for driving the console with Textual's pilot: what is on screen, as text."""

from __future__ import annotations

from textual.app import App
from textual.widgets import RichLog, Static


def screen_text(app: App) -> str:
    """Every character the terminal would show now, one line per row."""
    return "\n".join(strip.text for strip in app.screen._compositor.render_strips())


def log_text(app: App, pane: str) -> str:
    log = app.query_one(f"#{pane}", RichLog)
    return "\n".join(strip.text.rstrip() for strip in log.lines)


def static_text(app: App, widget_id: str) -> str:
    return str(app.query_one(f"#{widget_id}", Static).render())


async def settle(app: App, pilot, until=None, limit_s: float = 5.0) -> None:
    """Let worker threads (pass searches) finish and the screen catch up; with ``until``, keep
    pausing (0.1 s at a time, at most ``limit_s``) until it holds, so a loaded machine cannot
    make the screen be read before its refresh."""
    await app.workers.wait_for_complete()
    await pilot.pause(0.3)
    waited = 0.0
    while until is not None and not until() and waited < limit_s:
        await pilot.pause(0.1)
        waited += 0.1
