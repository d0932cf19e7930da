"""Autotracking (OrbitDRV's role): turn the server's ticks into rotor targets.

On every tick with ``TRACK ON``, :meth:`RotorCoupling.process`:

- at AOS, plans the whole pass once (:func:`nfwserver.rotor.flip.plan_pass`) in the flip mode
  (``"auto"``, ``"on"``, ``"off"``; :meth:`RotorCoupling.set_flip_mode` changes it at run time and
  re-plans a pass in progress): normal or flipped pointing and the azimuth branch that keeps the pass
  inside the rotor's range;
- while the satellite is up, aims ahead of it by the rotor's travel time (so the antennas are where
  the satellite will be when they arrive; never ahead below the horizon) and sends a new target only
  when it moved by at least ``threshold_deg`` (relays wear out).  A target the rotor cannot reach is
  ignored by the driver, never clamped; the first one in a pass is reported as an event;
- after LOS, parks (the driver's parking timer, or at once when the delay is 0) or pre-positions
  to the next pass's AOS, as configured; and the same at once when the selected satellite changes to one
  below the horizon (or to none: park), whoever changed it (``SAT=``, autotrack, a restart): the step
  reacts to the selection in the samples, so the rotor never stays pointing at the old satellite;
- lets the driver run its clock duties and reads the rotor back, reporting the sky position the
  antennas point at through ``on_position`` (the server's ``report_antenna_position``).

The driver's alarms (a stalled rotor) and the coupling's own events are reported through ``on_event(text)``
for the console and the event log, and logged.

It takes plain callables for the tracking engine, so it does not depend on the DDE core:
``predict(when) -> (az, el)`` and ``pass_track(when) -> [(when, az, el), ...]`` for the pass in
progress or the next one (from its AOS or from ``when``, to its LOS), or None.
"""

from __future__ import annotations

import logging
import math
import threading
from collections.abc import Callable, Sequence
from dataclasses import replace
from datetime import datetime, timedelta

from nfwserver.core.sample import TickSample
from nfwserver.core.tick_worker import TickWorker
from nfwserver.rotor.flip import FLIP_MODES, PassPlan, flip, plan_pass
from nfwserver.rotor.geometry import unwrap
from nfwserver.rotor.kct_annunciator import Announcement, describe
from nfwserver.rotor.kct_driver import KctDriver

__all__ = ["AFTER_LOS", "FLIP_MODES", "RotorCoupling", "angular_distance", "sky_from_rotor"]

log = logging.getLogger(__name__)

Predict = Callable[[datetime], tuple[float, float] | None]
PassTrack = Callable[[datetime], Sequence[tuple[datetime, float, float]] | None]
AFTER_LOS = ("park", "next-aos", "stay")


def angular_distance(az1: float, el1: float, az2: float, el2: float) -> float:
    """Great-circle angle (deg) between two sky directions."""
    a1, e1, a2, e2 = map(math.radians, (az1, el1, az2, el2))
    c = math.sin(e1) * math.sin(e2) + math.cos(e1) * math.cos(e2) * math.cos(a1 - a2)
    return math.degrees(math.acos(min(1.0, max(-1.0, c))))


def sky_from_rotor(rotor_az: float, rotor_el: float) -> tuple[float, float]:
    """Sky (az, el) a rotor position points at (elevation beyond 90 means flipped)."""
    if rotor_el > 90.0:
        return (rotor_az + 180.0) % 360.0, 180.0 - rotor_el
    return rotor_az % 360.0, rotor_el


class RotorCoupling(TickWorker):
    """Drives ``driver`` from ticks; see the module docstring."""

    thread_name = "nfw-rotor"

    def __init__(self, driver: KctDriver, predict: Predict, pass_track: PassTrack, threshold_deg: float = 2.0,
                 speed_deg_s: float = 6.0, max_lead_s: float = 10.0, after_los: str = "park", flip_mode: str = "auto",
                 on_position: Callable[[float, float], None] | None = None,
                 on_event: Callable[[str], None] | None = None) -> None:
        super().__init__(driver.clock)
        if after_los not in AFTER_LOS or flip_mode not in FLIP_MODES:
            raise ValueError(f"after_los must be one of {AFTER_LOS} and flip_mode one of {FLIP_MODES}")
        if threshold_deg < 0 or speed_deg_s <= 0 or max_lead_s < 0:
            raise ValueError("threshold must be >= 0, speed > 0 and max lead >= 0")
        self.driver = driver
        self.predict = predict
        self.pass_track = pass_track
        self.threshold_deg = threshold_deg
        self.speed_deg_s = speed_deg_s
        self.max_lead_s = max_lead_s
        self.after_los = after_los
        self.flip_mode = flip_mode
        self.on_position = on_position
        self.on_event = on_event
        self.plan: PassPlan | None = None
        self.flip_state = flip_mode == "on"  #: inverted pointing now (what FlipAnts' 7E reports)
        self._sent: tuple[float, float] | None = None  # sky (az, el) of the last target sent
        self._tracking = False  # autotracking was active on the last tick
        self._track_on_seen = False
        self._replan = False
        self._unreachable_reported = False
        self._catalog_number: int | None = None  # the satellite the plan belongs to
        self._seen_satellite = False
        self._switched = False  # the selection changed: the rotor is placed for the new one at this tick
        # Guards flip_mode, flip_state, _replan and _retry_asked, which set_flip_mode writes from other
        # threads (TCP, console); never held across a call into the driver or the tracking engine.
        self._lock = threading.Lock()
        self._retry_asked = False  # an operator's action asked for a stalled rotor to be tried at once
        self._park_asked = False  # PARK asked for; done at the next tick
        #: when PARK was asked for: samples computed until then, still marked tracking, are not followed
        self._parked_at: datetime | None = None
        driver.annunciator.listeners.append(self._announced)

    # -- events and run-time controls ----------------------------------------------------
    def _event(self, text: str, level: int = logging.INFO) -> None:
        log.log(level, "rotor: %s", text)
        if self.on_event is not None:
            try:
                self.on_event(text)
            except Exception:
                log.exception("rotor event listener failed")

    def _announced(self, item: Announcement) -> None:
        if self.on_event is None:
            return
        try:
            self.on_event(describe(item))
        except Exception:
            log.exception("rotor event listener failed")

    def request_park(self) -> None:
        """Send the rotor to its park position at its next tick (``PARK``; any thread may call this).  The
        caller switches tracking off; samples still marked tracking that were computed before are not
        followed, so the rotor stays parked until a later ``TRACK ON``."""
        with self._lock:
            self._park_asked = True
            self._parked_at = self.driver.clock.now()
        self._event("parking: tracking off, rotor to its park position")

    def set_flip_mode(self, mode: str) -> None:
        """``"auto"``, ``"on"`` or ``"off"`` from now on; a pass in progress is re-planned at the next tick.

        Any thread may call this (TCP, console): it only records the choice under the coupling's lock; the
        rotor itself (re-planning, re-trying a stalled rotor) is driven from the coupling's own thread at
        its next tick, never from the caller's.
        """
        if mode not in FLIP_MODES:
            raise ValueError(f"flip mode must be one of {FLIP_MODES}, not {mode!r}")
        with self._lock:
            self.flip_mode = mode
            self._replan = True
            self._retry_asked = True  # an operator's action: a stalled rotor is tried again at once
            if mode != "auto":
                self.flip_state = mode == "on"
        note = ""
        if mode == "on" and not self.driver.geometry.can_flip:
            note = (f"; this rotor's elevation stops at {self.driver.geometry.el_max:g} deg, so inverted targets "
                    "are out of reach and will be ignored")
        self._event(f"flip mode {mode}{note}", logging.WARNING if note else logging.INFO)

    # -- planning --------------------------------------------------------------------------
    def _plan(self, track: Sequence[tuple[datetime, float, float]], mode: str) -> PassPlan:
        sky = [(az, el) for _, az, el in track]
        pos = self.driver.rotor_position()
        plan = plan_pass(self.driver.geometry, sky, pos[0] if pos is not None else None, mode)
        if not plan.fits:
            log.warning("this pass does not fit the rotor's range in flip mode %s; targets beyond the stops "
                        "will be ignored", mode)
        if sky:
            azs = [flip(az, el)[0] if plan.flipped else az for az, el in sky]
            self.driver.set_reference_azimuth(unwrap(azs)[0] + plan.offset_deg if plan.fits else azs[0])
        return plan

    def _start_pass(self, when: datetime, mode: str) -> None:
        track = self.pass_track(when) or []
        self.plan = self._plan(track, mode)
        with self._lock:
            if not self._replan:  # else a newer flip mode arrived meanwhile: its state stands until its re-plan
                self.flip_state = self.plan.flipped
        self._sent = None
        self._unreachable_reported = False
        self.driver.stop_parking_timer()
        log.info("AOS: pass planned %s", "flipped" if self.plan.flipped else "normal")

    def _end_pass(self, when: datetime) -> None:
        self.plan = None
        if self.after_los == "park":
            params = self.driver.parking_parameters()
            if params.delay_minutes > 0:
                self.driver.start_parking_timer()
            else:
                self.driver.set_target(azimuth_deg=params.azimuth_deg, elevation_deg=params.elevation_deg)
        elif self.after_los == "next-aos":
            track = self.pass_track(when + timedelta(seconds=1))
            if track:
                plan = self._plan(track, self.flip_mode)
                _, az, el = track[0]
                el = max(el, 0.0)  # AOS lies on the horizon
                az_k, el_k = flip(az, el) if plan.flipped else (az, el)
                self.driver.set_target(azimuth_deg=az_k, elevation_deg=el_k)

    def _park_now(self) -> None:
        self.plan = None
        self._sent = None
        self.driver.stop_parking_timer()
        params = self.driver.parking_parameters()
        self.driver.set_target(azimuth_deg=params.azimuth_deg, elevation_deg=params.elevation_deg)

    # -- per tick --------------------------------------------------------------------------
    def process(self, sample: TickSample) -> None:
        """One tick's work (the worker's step; tests call it directly)."""
        with self._lock:  # one look at what other threads asked for
            retry, self._retry_asked = self._retry_asked, False
            park, self._park_asked = self._park_asked, False
            parked_at = self._parked_at
            if parked_at is not None and sample.time > parked_at:
                self._parked_at = None  # a sample from after the PARK: its tracking flag is current from now on
        if retry:
            self.driver.retry_now()
        if park:
            self._park_now()
        if parked_at is not None and sample.time <= parked_at and sample.tracking:
            sample = replace(sample, tracking=False)  # computed before PARK's TRACK OFF: not followed
        if sample.tracking and not self._track_on_seen:
            self.driver.retry_now()  # a new TRACK ON tries a stalled rotor again at once
        self._track_on_seen = sample.tracking
        if sample.catalog_number != self._catalog_number or not self._seen_satellite:
            self._satellite_changed(sample.catalog_number)
        switched, self._switched = self._switched, False
        self._tracking = sample.tracking
        la = sample.look_angles
        if self._tracking and la is not None:
            if sample.above_horizon:
                with self._lock:
                    replan, self._replan = self.plan is None or self._replan, False
                    mode = self.flip_mode
                if replan:
                    self._start_pass(sample.time, mode)
                az, el = self._aim(sample.time, la.azimuth_deg, la.elevation_deg)
                if self._sent is None or angular_distance(az, el, *self._sent) >= self.threshold_deg:
                    self._send(az, el)
            elif self.plan is not None or switched:  # a LOS, or a new satellite below the horizon
                self._end_pass(sample.time)
        elif self._tracking and switched and sample.catalog_number is None and self.after_los == "park":
            self._end_pass(sample.time)  # no satellite any more: nothing to pre-position for
        elif not self._tracking:
            self.plan = None
        self.driver.service()
        pos = self.driver.rotor_position()
        if pos is not None and self.on_position is not None:
            self.on_position(*sky_from_rotor(*pos))

    def _satellite_changed(self, catalog_number: int | None) -> None:
        """Another satellite (or the first since the start): nothing planned for the old one survives (pass
        plan, flip decision, azimuth branch, last target), a stalled rotor is tried again at once for the new
        one, and this tick places the rotor for it (see :meth:`process`)."""
        first = not self._seen_satellite
        self._catalog_number = catalog_number
        self._seen_satellite = True
        self._switched = True
        if first:
            return
        self.plan = None
        self._sent = None
        self._unreachable_reported = False
        with self._lock:
            if self.flip_mode == "auto":
                self.flip_state = False
        self.driver.retry_now()

    def _send(self, az: float, el: float) -> None:
        az_k, el_k = flip(az, el) if self.plan and self.plan.flipped else (az % 360.0, el)
        if self.driver.set_target(azimuth_deg=az_k, elevation_deg=el_k):
            self._sent = (az, el)
        elif not self._unreachable_reported:
            self._unreachable_reported = True
            self._event(f"target az {az_k:.1f} el {el_k:.1f} is out of this rotor's reach: ignored, not clamped "
                        "(the antennas stay where they were)", logging.WARNING)

    def _aim(self, when: datetime, az: float, el: float) -> tuple[float, float]:
        """Where to point: the satellite's position one rotor travel time ahead (never below the horizon)."""
        pos = self.driver.rotor_position()
        if pos is None or self.max_lead_s == 0:
            return az, el
        travel = angular_distance(az, el, *sky_from_rotor(*pos)) / self.speed_deg_s
        lead = min(self.max_lead_s, travel)
        if lead < 0.5:
            return az, el
        ahead = self.predict(when + timedelta(seconds=lead))
        if ahead is None or ahead[1] < 0.0 <= el:
            return az, el
        return ahead

    def stop(self) -> None:
        super().stop()
        self.driver.backend.close()
