"""What a running station does with a change of its configuration file, said by ``config set`` itself.

The answer comes from the station's own table (:data:`~nfwserver.app.live_config.CONFIG_PARTS`), the one its
live reload uses, so the command and the station never disagree: parts the station applies at once, parts
that wait for a restart (named), and settings read only when a station starts (the start-up satellite,
``tune``, ``track``, the state file, the mode schedules), which a running station leaves as they are.
"""

from __future__ import annotations

from nfwserver.app.live_config import CONFIG_PARTS
from nfwserver.config.live_reload import restart_needed
from nfwserver.config.schema import Config

__all__ = ["change_note"]

#: Settings used only when a station starts: a running one keeps what it started with (or was told since).
START_ONLY = (("server", "satellite"), ("server", "tune"), ("server", "track"), ("state_file",), ("schedules",))


def _get(config: object, path: tuple[str, ...]) -> object:
    for name in path:
        config = getattr(config, name)
    return config


def change_note(old: Config, new: Config) -> str:
    """One sentence on how a running station takes the change from ``old`` to ``new`` ("" when nothing that a
    station uses changed)."""
    restart = restart_needed(CONFIG_PARTS, old, new)
    if restart:
        return f"a running station needs a restart to apply {', '.join(restart)}"
    if any(part.apply is not None and part.differs(old, new) for part in CONFIG_PARTS):
        return "a running station applies it within seconds"
    if any(_get(old, path) != _get(new, path) for path in START_ONLY):
        return "used when the station starts; a running station keeps its current setting"
    if old.favourites != new.favourites:
        return "a running station uses it the next time it lists passes"
    return ""
