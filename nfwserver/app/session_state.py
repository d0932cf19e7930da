"""The session state kept across restarts: the AutoTracking satellite, and autotrack on or off.

Saved as a small JSON file, atomically (:mod:`nfwserver.storage`, keeping the file's permissions),
whenever it changes, and at stop from the live state; a missing, unreadable or malformed file just means
"no saved state".  Temporaries left by a process killed mid-save are removed when the state file is
opened.  The file also records which ``[server] satellite`` was configured when the choice was made, so an
edit of the configuration wins over a choice saved before it (the station says so in its log); likewise for
autotrack, on or off (and why off) with the ``[autotrack] enabled`` of the time.  Writes are atomic and made
under the file's lock (:func:`nfwserver.file_lock.locked`), so two stations given one state file cannot
interleave theirs.

:class:`SessionSaver` follows the ticks on its own worker thread: saving (an fsync) never runs on
the publisher.  A file that cannot be written (read-only, full disk, a removed directory) is the
``state-file`` link's fault: one warning, visible in STATUS while it lasts, retried with a bounded
back-off (never once per tick), cleared by the first save that succeeds; the choice stays in memory.
"""

from __future__ import annotations

import json
import logging
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path

from nfwserver.config.files import read_regular_bytes
from nfwserver.core.sample import TickSample
from nfwserver.core.tick_worker import TickWorker
from nfwserver.file_lock import locked
from nfwserver.health import LinkHealth
from nfwserver.storage import atomic_write_text, remove_stale_temporaries

log = logging.getLogger(__name__)

#: Longest wait for the state file's lock (real seconds); a longer hold is a failed save, tried again.
LOCK_WAIT_S = 2.0
#: Bytes of the largest state file read (a saved state is about 200); a larger one is not the station's.
MAX_STATE_BYTES = 16 * 1024
#: Characters of the longest reason autotrack may be off for that is read back as it is (the state file's own
#: path is part of it after a restart); a longer one, or one with control characters, is cut and cleaned.
MAX_REASON_CHARS = 1000


@dataclass(frozen=True)
class SessionState:
    satellite: int | None = None  #: the AutoTracking satellite chosen while running
    configured: int | None = None  #: ``[server] satellite`` at the time of that choice
    autotrack: bool | None = None  #: autotrack on or off (None: not recorded)
    autotrack_off: str | None = None  #: why it was off
    autotrack_enabled: bool | None = None  #: ``[autotrack] enabled`` at that time

    def with_autotrack(self, mode: tuple[bool, str | None] | None, enabled: bool | None) -> SessionState:
        """This state with autotrack's ``mode`` (on, why off) recorded, when there is one."""
        if mode is None:
            return self
        return SessionState(self.satellite, self.configured, mode[0], mode[1], enabled)


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
            doc = json.loads(read_regular_bytes(self.path, MAX_STATE_BYTES).decode("utf-8"))  # never a FIFO's wait
            numbers = [doc.get("satellite"), doc.get("configured")]
            for number in numbers:
                if number is not None and (isinstance(number, bool) or not isinstance(number, int)):
                    raise ValueError("satellite is not a catalog number")
            auto = [doc.get("autotrack"), doc.get("autotrack_off"), doc.get("autotrack_enabled")]
            if not all(v is None or isinstance(v, t) for v, t in zip(auto, (bool, str, bool), strict=True)):
                raise ValueError("autotrack is not on/off with a reason")
            reason = auto[1]
            if isinstance(reason, str) and (len(reason) > MAX_REASON_CHARS or not reason.isprintable()):
                log.warning("the reason autotrack was off in %s is not one line of at most %d printable "
                            "characters: cut and cleaned", self.path, MAX_REASON_CHARS)
                auto[1] = " ".join("".join(ch if ch.isprintable() else " " for ch in reason).split())[
                    :MAX_REASON_CHARS]
            state = SessionState(*numbers, *auto)
        except FileNotFoundError:
            state = SessionState()
        except RecursionError:  # "[[[[..." deeper than the interpreter's stack
            log.warning("ignoring the saved session state in %s: nested too deeply", self.path)
            state = SessionState()
        except (OSError, ValueError, AttributeError) as exc:
            log.warning("ignoring the saved session state in %s: %s", self.path, exc)
            state = SessionState()
        self._last = state
        return state

    def saved(self, state: SessionState) -> bool:
        """True when ``state`` is what was last loaded or saved (nothing to write)."""
        return state == self._last

    def save(self, state: SessionState) -> None:
        """Write ``state`` if it differs from what was last loaded or saved; raises :class:`OSError`."""
        if state == self._last:
            return
        with locked(self.path, timeout_s=LOCK_WAIT_S):
            atomic_write_text(self.path, json.dumps(asdict(state)) + "\n")
        self._last = state


class SessionSaver(TickWorker):
    """Saves the AutoTracking satellite and autotrack's mode when they change, on the worker thread ``nfw-session``.

    ``health`` is the ``state-file`` link: failures back off on its schedule.  When the saver stops, the
    state is saved once more, whatever the back-off says: the live selection read from ``current`` (a
    ``SAT=`` answered ``OK`` after the last tick is not lost), else the last tick's."""

    thread_name = "nfw-session"

    def __init__(self, state_file: StateFile, configured: int | None, health: LinkHealth,
                 current: Callable[[], int | None] | None = None,
                 autotrack: Callable[[], tuple[bool, str | None]] | None = None,
                 autotrack_enabled: bool | None = None) -> None:
        super().__init__(health.clock)
        self.state_file = state_file
        self.configured = configured
        self.health = health
        self.current = current
        self.autotrack = autotrack  #: autotrack's mode (on, why off), read at each save
        self.autotrack_enabled = autotrack_enabled  #: ``[autotrack] enabled`` of the running configuration
        self._wanted: SessionState | None = None

    def _state(self, satellite: int | None) -> SessionState:
        mode = self.autotrack() if self.autotrack is not None else None
        return SessionState(satellite, self.configured).with_autotrack(mode, self.autotrack_enabled)

    def process(self, sample: TickSample) -> None:
        self._wanted = self._state(sample.catalog_number)
        self._write(self._wanted, forced=False)

    def stop(self) -> None:
        super().stop()
        if self.current is not None:
            self._wanted = self._state(self.current())
        if self._wanted is not None:
            self._write(self._wanted, forced=True)

    def _write(self, state: SessionState, forced: bool) -> None:
        if self.state_file.saved(state):
            self.health.succeeded()  # nothing left unsaved
            return
        if not (forced or self.health.may_try()):
            return
        try:
            self.state_file.save(state)
        except OSError as exc:
            self.health.failed(f"cannot save the session state to {self.state_file.path} "
                               f"({exc.strerror or exc}); keeping it in memory")
        else:
            self.health.succeeded()
