"""Stall detection for the KCT status bits 20h / 10h ("ELEV / AZIM rotor is stalled & has been disabled").

An axis is declared stalled when

- the backend itself says so (the simulated rotor's injected stall, :class:`StallReporting`);
- it needs moving (more than ``deadband_deg`` from where it was sent: real controllers stop a degree
  or two short, and that is arrival, not a stall) and has not moved ``tolerance_deg`` towards the
  target within ``timeout_s`` of clock time (a jammed rotor that reports nothing); or
- the backend refused ``error_limit`` calls in a row (``RPRT -n`` from rotctld): then both axes,
  as the daemon does not say which one failed.

Before a stall is declared, an axis off its target that has not made progress for ``idle_grace_s``
(:meth:`StallWatch.idle_axes`) is neither where it was told nor moving there: the driver shows that as
its own state (``off-target``), never as ``ok``.  Progress is watched even without a no-movement
timeout (``timeout_s`` None), which then only declares no stalls.

A stalled axis stays stalled until :meth:`StallWatch.reset` (the driver's Enable call) or
:meth:`StallWatch.probe` (the driver trying again after its back-off, or at an operator's action).  A
probe is on probation: one refusal declares the stall again at once (not three), and the watch notes
whether the rotor then made progress (:attr:`StallWatch.progressed`), which is what clears the fault.
Times are ``clock.monotonic()`` seconds; angles are the rotor frame, degrees.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

AXES = ("azimuth", "elevation")


@runtime_checkable
class StallReporting(Protocol):
    """A backend that knows when an axis is stalled (optional for backends)."""

    def stalled_axes(self) -> tuple[bool, bool]:
        """(azimuth stalled, elevation stalled)."""
        ...


@dataclass
class _Progress:
    reference: float | None = None  #: axis position when progress was last seen
    since: float | None = None  #: monotonic time of that


@dataclass
class StallWatch:
    timeout_s: float | None = 15.0  #: None: no no-movement detection (e.g. a virtual clock with a real rotor)
    tolerance_deg: float = 1.0  #: movement towards the target that counts as progress
    deadband_deg: float = 3.0  #: closer than this to the target, an axis needs no moving
    error_limit: int = 3
    #: a rotor off its target without progress for this long is shown as such (before any stall)
    idle_grace_s: float = 3.0
    stalled: list[bool] = field(default_factory=lambda: [False, False])  #: [azimuth, elevation]
    errors: int = 0  #: backend refusals in a row
    progressed: bool = False  #: since the last reset or probe, every axis moved toward its target or arrived
    _moved: list[bool] = field(default_factory=lambda: [False, False])
    _progress: list[_Progress] = field(default_factory=lambda: [_Progress(), _Progress()])

    def reset(self) -> None:
        self.stalled = [False, False]
        self.errors = 0
        self.progressed = False
        self._moved = [False, False]
        self._progress = [_Progress(), _Progress()]

    def lost_sight(self) -> None:
        """The rotor cannot be read (its daemon is away): time without a reading is not time without
        movement, so the no-movement timers start afresh at the next reading."""
        self._progress = [_Progress(), _Progress()]

    def forget_progress(self) -> None:
        """A move was refused: progress seen before it says nothing about the rotor now."""
        self.progressed = False
        self._moved = [False, False]

    def probe(self) -> None:
        """Re-arm the stalled axes on probation: the next refusal declares them stalled again."""
        self.reset()
        self.errors = self.error_limit - 1

    def backend_ok(self) -> None:
        self.errors = 0

    def backend_error(self, axes: int) -> list[int]:
        """A refused call; returns the axes newly declared stalled (``axes``: 1 or 2 installed)."""
        self.errors += 1
        if self.errors < self.error_limit:
            return []
        return self._declare(range(axes))

    def reported(self, report: tuple[bool, bool]) -> list[int]:
        """The backend's own stall report; returns the axes newly declared stalled."""
        return self._declare(i for i in range(2) if report[i])

    def observe(self, now: float, sent: tuple[float, float] | None, position: tuple[float, float],
                axes: int) -> list[int]:
        """A position read; returns the axes newly declared stalled for not moving toward ``sent``.

        Progress is movement of at least ``tolerance_deg`` towards the target since the last progress,
        so a rotor that lags behind a fast satellite but keeps turning is not declared stalled.
        """
        if sent is None:
            return []
        newly = []
        for i in range(axes):
            p = self._progress[i]
            if abs(sent[i] - position[i]) <= self.deadband_deg:
                self._progress[i] = _Progress(position[i], now)
                self._moved[i] = True
                continue
            if p.reference is None or p.since is None:
                self._progress[i] = _Progress(position[i], now)
                continue
            moved = position[i] - p.reference
            if abs(moved) >= self.tolerance_deg and (moved > 0) == (sent[i] > p.reference):
                self._progress[i] = _Progress(position[i], now)
                self._moved[i] = True
            elif self.timeout_s is not None and now - p.since >= self.timeout_s:
                newly.append(i)
        self.progressed = all(self._moved[:axes])
        return self._declare(newly)

    def idle_axes(self, now: float, sent: tuple[float, float] | None, position: tuple[float, float] | None,
                  axes: int) -> list[int]:
        """The axes that are neither where they were sent (beyond ``deadband_deg``) nor seen moving there for
        ``idle_grace_s`` seconds (``now`` as for :meth:`observe`, after it); none while nothing was sent or
        nothing read back.  A stalled axis is one of these that the watch has also given up on."""
        if sent is None or position is None:
            return []
        grace = self.idle_grace_s if self.timeout_s is None else min(self.idle_grace_s, self.timeout_s)
        idle = []
        for i in range(axes):
            since = self._progress[i].since
            if abs(sent[i] - position[i]) > self.deadband_deg and since is not None and now - since >= grace:
                idle.append(i)
        return idle

    def _declare(self, axes: Iterable[int]) -> list[int]:
        newly = [i for i in axes if not self.stalled[i]]
        for i in newly:
            self.stalled[i] = True
        return newly
