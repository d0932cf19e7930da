"""The session state kept across restarts: the AutoTracking satellite.

Saved as a small JSON file, atomically (:mod:`nfwserver.storage`, keeping the file's permissions),
whenever it changes; a missing, unreadable or malformed file just means "no saved state".  Temporaries
left by a process killed mid-save are removed when the state file is opened.  The file also records
which ``[server] satellite`` was configured when the choice was made, so an edit of the configuration
wins over a choice saved before it (the station says so in its log).

:class:`SessionSaver` follows the ticks on its own worker thread: saving (an fsync) never runs on
the publisher.
"""

from __future__ import annotations

import json
import logging
from dataclasses import asdict, dataclass
from pathlib import Path

from nfwserver.core.sample import TickSample
from nfwserver.core.tick_worker import TickWorker
from nfwserver.storage import atomic_write_text, remove_stale_temporaries

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class SessionState:
    satellite: int | None = None  #: the AutoTracking satellite chosen while running
    configured: int | None = None  #: ``[server] satellite`` at the time of that choice


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
            numbers = [doc.get("satellite"), doc.get("configured")]
            for number in numbers:
                if number is not None and (isinstance(number, bool) or not isinstance(number, int)):
                    raise ValueError("satellite is not a catalog number")
            state = SessionState(*numbers)
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


class SessionSaver(TickWorker):
    """Saves the AutoTracking satellite when it changes, on the worker thread ``nfw-session``."""

    thread_name = "nfw-session"

    def __init__(self, state_file: StateFile, configured: int | None) -> None:
        super().__init__()
        self.state_file = state_file
        self.configured = configured

    def process(self, sample: TickSample) -> None:
        self.state_file.save(SessionState(sample.catalog_number, self.configured))
