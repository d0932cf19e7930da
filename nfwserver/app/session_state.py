"""The session state kept across restarts: the AutoTracking satellite.

Saved as a small JSON file, atomically (:mod:`nfwserver.storage`, keeping the file's permissions),
whenever it changes; a missing, unreadable or malformed file just means "no saved state".  Temporaries
left by a process killed mid-save are removed when the state file is opened.
"""

from __future__ import annotations

import json
import logging
from dataclasses import asdict, dataclass
from pathlib import Path

from nfwserver.storage import atomic_write_text, remove_stale_temporaries

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class SessionState:
    satellite: int | None = None


def default_state_path() -> Path:
    from platformdirs import user_state_dir

    return Path(user_state_dir("nfwserver", appauthor=False)) / "state.json"


class StateFile:
    def __init__(self, path: str | Path | None = None) -> None:
        self.path = Path(path) if path is not None else default_state_path()
        self._last: SessionState | None = None
        for stale in remove_stale_temporaries(self.path):
            log.info("removed %s, left by an interrupted save", stale.name)

    def load(self) -> SessionState:
        try:
            doc = json.loads(self.path.read_text(encoding="utf-8"))
            satellite = doc.get("satellite")
            if satellite is not None and (isinstance(satellite, bool) or not isinstance(satellite, int)):
                raise ValueError("satellite is not a catalog number")
            state = SessionState(satellite)
        except FileNotFoundError:
            state = SessionState()
        except (OSError, ValueError, AttributeError) as exc:
            log.warning("ignoring the saved session state in %s: %s", self.path, exc)
            state = SessionState()
        self._last = state
        return state

    def save(self, state: SessionState) -> None:
        """Write ``state`` if it differs from what was last loaded or saved."""
        if state == self._last:
            return
        try:
            atomic_write_text(self.path, json.dumps(asdict(state)) + "\n")
            self._last = state
        except OSError as exc:
            log.error("cannot save the session state to %s: %s", self.path, exc)
