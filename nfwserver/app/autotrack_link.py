"""The station's autotrack: the schedule runtime (:mod:`nfwserver.autotrack`) wired to one station core.

The runtime selects through :meth:`~nfwserver.core.station_core.StationCore.select_scheduled` (which refuses
once a client's ``SAT=`` has switched it off) and is the core's :attr:`~StationCore.autotrack`, which
``AUTO ON|OFF`` switches and any accepted ``SAT=`` switches off.  It plans again when what its passes depend on
changes: the elements or the observer and horizon (:attr:`StationState.sky_generation`) or the ``[autotrack]``
settings of the running configuration (read at each tick, so a reload is followed at once).

``nfwserver run`` follows the ticks on the runtime's own thread (:meth:`start`); ``nfwserver simulate`` calls
:meth:`follow` before each tick on virtual time, so every tick names the schedule's satellite of its instant.
On or off, and why off, is kept across restarts in the session state file (:meth:`restore`).
"""

from __future__ import annotations

from collections.abc import Callable
from datetime import datetime

from nfwserver.autotrack import AutotrackRuntime, AutotrackSettings, StationPlanner
from nfwserver.autotrack.planner import list_warning
from nfwserver.autotrack.runtime import NOT_SWITCHED_ON
from nfwserver.autotrack.worker import AutotrackWorker
from nfwserver.clock import Clock
from nfwserver.config.schema import Config
from nfwserver.core.sample import TickSample
from nfwserver.core.station_core import StationCore
from nfwserver.tracking.horizon import HorizonTable
from nfwserver.tracking.observer import Observer

__all__ = ["StationAutotrack"]

_KEPT = " (before the restart, kept in "  #: what a restart adds to the reason autotrack is off


class StationAutotrack:
    """Autotrack on ``core``, with the ``[autotrack]`` settings of ``config()`` (the running configuration)."""

    def __init__(self, core: StationCore, clock: Clock, config: Callable[[], Config]) -> None:
        self.core = core
        self.config = config
        self._settings = AutotrackSettings.of(config())
        self._sky = core.state.sky_generation
        planner = StationPlanner(lambda: core.state.catalog, self._sky_now, lambda: self._settings)
        self.runtime = AutotrackRuntime(planner, core.select_scheduled, list_warning=lambda: list_warning(
            AutotrackSettings.of(config()).satellites, core.state.catalog))
        core.autotrack = self.runtime
        self.worker = AutotrackWorker(self.runtime, clock)
        self._unsubscribe: list[Callable[[], None]] = []

    def _sky_now(self) -> tuple[Observer, HorizonTable, float]:
        snap = self.core.state.snapshot()
        if snap.observer is None:
            raise ValueError("no observer is configured ([observer] location)")
        return snap.observer, snap.horizon, snap.ut1_utc_s

    def _notice_changes(self) -> None:
        """Plan again when the elements, the sky or the settings changed (cheap: on the publish thread)."""
        settings, sky = AutotrackSettings.of(self.config()), self.core.state.sky_generation
        if settings != self._settings or sky != self._sky:
            self._settings, self._sky = settings, sky
            self.runtime.replan()

    def _wanted(self) -> bool:
        """Whether to follow the ticks: while on, or while off with an ``[autotrack] satellites`` list of its own
        and an observer (its schedule is shown); a station that does not use autotrack plans nothing."""
        listed = self.config().autotrack.satellites is not None
        return self.runtime.on or (listed and self.core.state.observer is not None)

    def _on_tick(self, sample: TickSample) -> None:
        self._notice_changes()
        if self._wanted():
            self.worker.on_tick(sample)

    def follow(self, now: datetime) -> int | None:
        """One step at ``now`` on the caller's thread (virtual time): returns the catalog number selected, if any."""
        self._notice_changes()
        return self.runtime.tick(now) if self._wanted() else None

    def restore(self, saved_on: bool | None, saved_off: str | None, saved_enabled: bool | None, where: str) -> str:
        """Switch on or off at start: as it was when the station stopped (``saved_*``, from the state file at
        ``where``) while ``[autotrack] enabled`` is what it was then, else as ``enabled`` says.  Returns the
        sentence for the log."""
        enabled = self.config().autotrack.enabled
        if saved_on is not None and saved_enabled == enabled:
            said = (saved_off or NOT_SWITCHED_ON).split(_KEPT, 1)[0]  # said once, however many restarts since
            on, why = saved_on, f"{said}{_KEPT}{where})"
            origin = f"as it was before the restart ({where})"
        else:
            on, why, origin = enabled, NOT_SWITCHED_ON, "from [autotrack] enabled"
        if on:
            self.core.set_autotrack(True, "config")
        else:
            self.runtime.switch_off(why)
        return f"autotrack {'on' if on else 'off'} {origin}"

    def mode(self) -> tuple[bool, str | None]:
        """On, and why off (None while on): what the state file keeps."""
        status = self.runtime.status(self.core.clock.now())
        return status.on, status.off_reason

    def status_fields(self) -> dict[str, object]:
        """STATUS fields: ``auto`` (on/off), ``auto_next`` (the scheduled pass in progress or next, UTC),
        ``auto_off`` (why off), ``auto_problems`` (listed satellites it cannot use, and why) and
        ``autotrack_fault`` while planning or selecting fails."""
        status = self.runtime.status(self.core.clock.now())
        fields: dict[str, object] = {"auto": status.on, "auto_next": status.next_pass_text()}
        if not status.on:
            fields["auto_off"] = status.off_reason
        if status.fault is not None:
            fields["autotrack_fault"] = status.fault
        if status.problems:
            fields["auto_problems"] = "; ".join(status.problems)
        return fields

    def start(self) -> None:
        """Follow the station's ticks on the runtime's own thread."""
        self._unsubscribe = [self.core.subscribe(self._on_tick)]
        self.worker.start()

    def stop(self) -> None:
        for unsubscribe in self._unsubscribe:
            unsubscribe()
        self._unsubscribe = []
        self.worker.stop()
