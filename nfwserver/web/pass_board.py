"""Passes for the page, computed on a thread of their own (``nfw-web-passes``), never on the publish loop.

What it computes, for the instant of the computation (``docs/WEB.md`` gives the JSON):

- the passes of the favourites and the selected satellite over the next :data:`LIST_HOURS` hours that
  are not over: AOS/TCA/LOS (UTC), maximum elevation (degrees), duration (s) and, when the rotor can
  flip, whether the rotor's planner would fly the pass flipped;
- the selected satellite's current or next pass as a sky track (azimuth/elevation in degrees, every
  :data:`TRACK_STEP_S` s, or coarser so that a pass of any length, AO-10's 11 hours say, is drawn whole in
  at most :data:`MAX_TRACK_POINTS` points ending at LOS) with its AOS/TCA/LOS points, for the polar plot;
  a satellite that is up now and never sets (geostationary) gets ``always_up`` and its one point;
- the selected satellite's ground track (geodetic latitude, east longitude in degrees) from
  :data:`GROUND_BEFORE_S` before to :data:`GROUND_AFTER_S` after the instant, for the map;
- the horizon table as azimuth/elevation points every 5 degrees (the polar plot's mask);
- the autotrack schedule of the next :data:`LIST_HOURS` hours as a timeline
  (:mod:`~nfwserver.web.schedule_view`), when the station has one.

It recomputes when the live state changes (its generation), when the first listed pass is over, when
autotrack has a new schedule, and at least every :data:`REFRESH_S` seconds of the station's clock.  Readers
get the newest result whole (:meth:`PassBoard.result`): its version, the result and its encoding are
published as one reference, so a frame never carries a version whose result is not yet served.  The frame
carries ``version`` so a page fetches ``/api/passes`` again only when it changed.

A computation that fails is retried after :data:`RETRY_FIRST_S`, doubling up to :data:`REFRESH_S`
(station clock), whatever else would make it due; the failure is logged once per episode (the
traceback at DEBUG), shown on the page (``error`` in the result) until a computation succeeds, and the
first success after it is logged.
"""

from __future__ import annotations

import json
import logging
import math
import threading
from collections.abc import Callable, Sequence
from datetime import datetime, timedelta
from typing import TYPE_CHECKING

from nfwserver.clock import Clock
from nfwserver.core.state import StateSnapshot, StationState
from nfwserver.rotor.coupling import RotorCoupling
from nfwserver.rotor.flip import plan_pass
from nfwserver.tracking.catalog import Satellite
from nfwserver.tracking.derived import sub_satellite_point
from nfwserver.tracking.look_angles import LookAngleCalculator, PropagationError
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.passes import Pass, find_passes
from nfwserver.web.schedule_view import timeline_part
from nfwserver.web.state_view import iso

if TYPE_CHECKING:
    from sgp4.api import Satrec

    from nfwserver.autotrack.schedule import Schedule

log = logging.getLogger(__name__)

LIST_HOURS = 12.0
NEXT_PASS_HOURS = 24.0
TRACK_STEP_S = 10.0
MAX_TRACK_POINTS = 721  #: a longer pass is sampled more coarsely, never cut
GROUND_BEFORE_S = 45 * 60.0
GROUND_AFTER_S = 95 * 60.0
GROUND_STEP_S = 60.0
REFRESH_S = 120.0
RETRY_FIRST_S = 5.0  #: first retry after a failed computation (station clock seconds), then doubling
MAX_PASSES = 12


def _track(calc: LookAngleCalculator, satrec: Satrec, p: Pass, now: datetime) -> list[tuple[float, float]]:
    """The pass from AOS to LOS (both included) in at most :data:`MAX_TRACK_POINTS` points."""
    start = p.aos or min(now, p.tca)
    end = p.los or (max(now, p.tca) + timedelta(hours=NEXT_PASS_HOURS))  # a set beyond the search: a day on
    span = max(0.0, (end - start).total_seconds())
    steps = max(1, min(MAX_TRACK_POINTS - 1, math.ceil(span / TRACK_STEP_S)))
    out: list[tuple[float, float]] = []
    for i in range(steps + 1):
        la = calc.compute(satrec, start + timedelta(seconds=span * i / steps))
        out.append((round(la.azimuth_deg, 2), round(la.elevation_deg, 2)))
    return out


def _point(calc: LookAngleCalculator, satrec: Satrec, when: datetime | None) -> dict[str, object] | None:
    if when is None:
        return None
    la = calc.compute(satrec, when)
    return {"time": iso(when), "az": round(la.azimuth_deg, 2), "el": round(la.elevation_deg, 2)}


class PassBoard:
    """See the module docstring.  ``favourites`` is read at each computation (the live configuration),
    ``schedule`` (autotrack's newest schedule, None without one) at each computation and each check."""

    def __init__(self, state: StationState, clock: Clock, favourites: Callable[[], Sequence[int]],
                 rotor: RotorCoupling | None = None, schedule: Callable[[], Schedule | None] = lambda: None) -> None:
        self.state = state
        self.clock = clock
        self.favourites = favourites
        self.rotor = rotor
        self.schedule = schedule
        self._done_schedule: Schedule | None = None
        empty: dict[str, object] = {"version": 0, "computed_at": None, "passes": [], "left_out": [],
                                    "track": None, "ground_track": [], "horizon": [], "schedule": None,
                                    "error": None}
        #: (version, result, its JSON): replaced whole, so readers on other threads see one of them
        self._published: tuple[int, dict[str, object], bytes] = (0, empty, json.dumps(empty).encode())
        self._error: str | None = None  #: the failing computation's error while an episode lasts
        self._retry_s = 0.0  #: the current back-off after a failure (0: none)
        self._retry_at = -1e18  #: monotonic clock seconds before which a failed computation is not retried
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._done_generation = -1
        self._done_at = -1e18
        self._first_los: datetime | None = None

    @property
    def version(self) -> int:
        return self._published[0]

    def result(self) -> dict[str, object]:
        return self._published[1]

    def encoded(self) -> bytes:
        return self._published[2]

    def next_event(self, now: datetime) -> dict[str, object] | None:
        """AOS or LOS of the selected satellite's pass, with the seconds until it (negative: past)."""
        track = self.result().get("track")
        if not isinstance(track, dict):
            return None
        for kind in ("aos", "los"):
            point = track.get(kind)
            if isinstance(point, dict) and point.get("time"):
                when = datetime.fromisoformat(str(point["time"]).replace("Z", "+00:00"))
                if when > now:
                    return {"kind": kind.upper(), "time": point["time"], "seconds": (when - now).total_seconds()}
        return None

    # -- life cycle ------------------------------------------------------------------------------
    def start(self) -> None:
        if self._thread is None:
            self._stop.clear()
            self._thread = threading.Thread(target=self._run, name="nfw-web-passes", daemon=True)
            self._thread.start()

    def stop(self) -> None:
        if self._thread is not None:
            self._stop.set()
            self._wake.set()
            self._thread.join(5.0)
            self._thread = None

    def request(self) -> None:
        """Compute again soon (e.g. the favourites changed)."""
        self._done_generation = -1
        self._wake.set()

    def _due(self) -> bool:
        now = self.clock.now()
        if self._error is not None and self.clock.monotonic() < self._retry_at:
            return False  # backing off after a failure, whatever else changed
        return (self.state.generation != self._done_generation
                or self.clock.monotonic() - self._done_at >= REFRESH_S
                or (self._first_los is not None and now >= self._first_los)
                or self.schedule() is not self._done_schedule
                or self._error is not None)

    def _run(self) -> None:
        while not self._stop.is_set():
            self.step()
            self.clock.wait(self._wake, 1.0)
            self._wake.clear()

    def step(self) -> bool:
        """Compute if it is due (the board thread's one round); True when a computation was tried."""
        if not self._due():
            return False
        try:
            self.compute()
        except Exception as exc:  # keep the board alive; the page shows the failure and the last result
            self._failed(exc)
        return True

    def _failed(self, exc: Exception) -> None:
        """One failed computation: back off, show it, and log it once for the episode."""
        error = f"the pass search failed: {type(exc).__name__}: {exc}"[:300]
        if self._error is None:
            log.warning("web: %s (retrying with back-off; the page shows it)", error)
            log.debug("web: pass search failure", exc_info=exc)
        self._error = error
        self._retry_s = min(REFRESH_S, self._retry_s * 2 if self._retry_s else RETRY_FIRST_S)
        self._retry_at = self.clock.monotonic() + self._retry_s
        version, result, _ = self._published
        shown = {**result, "version": version + 1, "error": error}
        self._published = (version + 1, shown, json.dumps(shown).encode())

    # -- the work ------------------------------------------------------------------------------------
    def compute(self) -> dict[str, object]:
        """Compute everything now (on the calling thread) and publish it as the newest result."""
        generation = self.state.generation
        snap = self.state.snapshot()
        now = self.clock.now()
        schedule = self.schedule()
        result: dict[str, object] = {"computed_at": iso(now), "passes": [], "left_out": [], "track": None,
                                     "ground_track": [],
                                     "horizon": [[az, round(snap.horizon.min_elevation(float(az)), 2)]
                                                 for az in range(0, 361, 5)],
                                     "schedule": timeline_part(schedule, now, LIST_HOURS)}
        observer, selected = snap.observer, snap.satellite
        if observer is not None:
            numbers = list(dict.fromkeys([*self.favourites(), *([selected.catalog_number] if selected else [])]))
            sats = [s for s in (snap.catalog.get(n) for n in numbers) if s is not None]
            searched = find_passes(sats, observer, now, now + timedelta(hours=LIST_HOURS), horizon=snap.horizon,
                                   ut1_utc=snap.ut1_utc_s) if sats else None
            found = [p for p in searched if p.los is None or p.los > now] if searched is not None else []
            # favourites whose positions cannot be computed now (decayed, elements far outside their validity)
            result["left_out"] = [sat.dde_name if (sat := snap.catalog.get(n)) is not None else str(n)
                                  for n in (searched.skipped if searched is not None else ())]
            calc = LookAngleCalculator(observer, snap.ut1_utc_s)
            rows = []
            for p in found[:MAX_PASSES]:
                sat = snap.catalog.get(p.catalog_number)
                rows.append(self._row(p, sat, calc, now))
            result["passes"] = rows
            self._first_los = found[0].los if found else None
            if selected is not None:
                result["track"] = self._selected_track(selected, found, observer, snap, calc, now)
                result["ground_track"] = self._ground_track(selected.satrec, now, snap.ut1_utc_s)
        version = self.version + 1
        result["version"], result["error"] = version, None
        self._published = (version, result, json.dumps(result).encode())  # one step: version and result
        self._done_generation, self._done_at = generation, self.clock.monotonic()
        self._done_schedule = schedule
        if self._error is not None:
            log.info("web: the pass search works again")
            self._error, self._retry_s = None, 0.0
        return result

    def _flipped(self, track: list[tuple[float, float]]) -> bool | None:
        rotor = self.rotor
        if rotor is None or not rotor.driver.geometry.can_flip or not track:
            return None
        try:
            return plan_pass(rotor.driver.geometry, track, None, rotor.flip_mode).flipped
        except ValueError:
            return None

    def _row(self, p: Pass, sat: Satellite | None, calc: LookAngleCalculator, now: datetime) -> dict[str, object]:
        flipped = None
        if sat is not None and self.rotor is not None:
            try:
                flipped = self._flipped(_track(calc, sat.satrec, p, now))
            except PropagationError:
                flipped = None
        return {"catalog_number": p.catalog_number, "name": sat.dde_name if sat is not None else str(p.catalog_number),
                "aos": iso(p.aos), "tca": iso(p.tca), "los": iso(p.los),
                "max_el": round(p.max_elevation_deg, 1), "duration_s": p.duration_s,
                "in_progress": p.aos is None or p.aos <= now, "flipped": flipped}

    def _selected_track(self, sat: Satellite, found: list[Pass], observer: Observer, snap: StateSnapshot,
                        calc: LookAngleCalculator, now: datetime) -> dict[str, object] | None:
        own = [p for p in found if p.catalog_number == sat.catalog_number]
        if not own:
            own = [p for p in find_passes([sat], observer, now, now + timedelta(hours=NEXT_PASS_HOURS),
                                          horizon=snap.horizon, ut1_utc=snap.ut1_utc_s)
                   if p.los is None or p.los > now]
        if not own or (own[0].aos is None and own[0].los is None):  # the search's pass of a satellite up throughout
            return self._always_up(sat, snap, calc, now)
        p = own[0]
        try:
            points = _track(calc, sat.satrec, p, now)
            return {"catalog_number": sat.catalog_number, "points": points,
                    "aos": _point(calc, sat.satrec, p.aos), "tca": _point(calc, sat.satrec, p.tca),
                    "los": _point(calc, sat.satrec, p.los), "max_el": round(p.max_elevation_deg, 1),
                    "flipped": self._flipped(points)}
        except PropagationError:
            return None

    @staticmethod
    def _always_up(sat: Satellite, snap: StateSnapshot, calc: LookAngleCalculator,
                   now: datetime) -> dict[str, object] | None:
        """No pass in the next day: a satellite above the horizon now is up all that time (a point); else None."""
        try:
            la = calc.compute(sat.satrec, now)
        except PropagationError:
            return None
        if la.elevation_deg < snap.horizon.min_elevation(la.azimuth_deg):
            return None
        point = (round(la.azimuth_deg, 2), round(la.elevation_deg, 2))
        return {"catalog_number": sat.catalog_number, "points": [point], "always_up": True,
                "aos": None, "tca": {"time": iso(now), "az": point[0], "el": point[1]}, "los": None,
                "max_el": point[1], "flipped": None}

    @staticmethod
    def _ground_track(satrec: Satrec, now: datetime, ut1_utc: float) -> list[list[float]]:
        out = []
        t = now - timedelta(seconds=GROUND_BEFORE_S)
        end = now + timedelta(seconds=GROUND_AFTER_S)
        while t <= end:
            point = sub_satellite_point(satrec, t, ut1_utc)
            if point is not None:
                out.append([round(point[0], 2), round(point[1], 2)])
            t += timedelta(seconds=GROUND_STEP_S)
        return out
