"""Autotracking (OrbitDRV's role): turn the server's ticks into rotor targets.

On every tick with ``TRACK ON``, :meth:`RotorCoupling.process`:

- at AOS, plans the whole pass once (:func:`nfwserver.rotor.flip.plan_pass`): normal or flipped
  pointing and the azimuth branch that keeps the pass inside the rotor's range; it never changes
  the plan mid-pass;
- while the satellite is up, aims ahead of it by the rotor's travel time (so the antennas are where
  the satellite will be when they arrive) and sends a new target only when it moved by at least
  ``threshold_deg`` (relays wear out);
- after LOS, parks (the driver's parking timer, or at once when the delay is 0) or pre-positions
  to the next pass's AOS, as configured;
- lets the driver run its clock duties and reads the rotor back, reporting the sky position the
  antennas point at through ``on_position`` (the server's ``report_antenna_position``).

It takes plain callables for the tracking engine, so it does not depend on the DDE core:
``predict(when) -> (az, el)`` and ``pass_track(when) -> [(when, az, el), ...]`` for the pass in
progress or the next one (from its AOS or from ``when``, to its LOS), or None.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Sequence
from datetime import datetime, timedelta

from nfwserver.core.sample import TickSample
from nfwserver.core.tick_worker import TickWorker
from nfwserver.rotor.flip import PassPlan, flip, plan_pass
from nfwserver.rotor.geometry import unwrap
from nfwserver.rotor.kct_driver import KctDriver

log = logging.getLogger(__name__)

Predict = Callable[[datetime], tuple[float, float] | None]
PassTrack = Callable[[datetime], Sequence[tuple[datetime, float, float]] | None]
AFTER_LOS = ("park", "next-aos", "stay")
FLIP_MODES = ("auto", "off")


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

    worker_name = "nfw-rotor"

    def __init__(self, driver: KctDriver, predict: Predict, pass_track: PassTrack, threshold_deg: float = 2.0,
                 speed_deg_s: float = 6.0, max_lead_s: float = 10.0, after_los: str = "park", flip_mode: str = "auto",
                 on_position: Callable[[float, float], None] | None = None) -> None:
        super().__init__()
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
        self.plan: PassPlan | None = None
        self.flip_state = False
        self._sent: tuple[float, float] | None = None  # sky (az, el) of the last target sent

    # -- planning --------------------------------------------------------------------------
    def _plan(self, track: Sequence[tuple[datetime, float, float]]) -> PassPlan:
        geometry = self.driver.geometry
        sky = [(az, el) for _, az, el in track]
        pos = self.driver.rotor_position()
        current = pos[0] if pos is not None else None
        if self.flip_mode == "off":
            plan = plan_pass(type(geometry)(geometry.az_min, geometry.az_max, geometry.el_min,
                                            min(geometry.el_max, 90.0)), sky, current)
        else:
            plan = plan_pass(geometry, sky, current)
        if not plan.fits:
            log.warning("this pass does not fit the rotor's range in any mode; following it as far as the stops allow")
        if sky:
            azs = [flip(az, el)[0] if plan.flipped else az for az, el in sky]
            self.driver.set_reference_azimuth(unwrap(azs)[0] + plan.offset_deg if plan.fits else azs[0])
        return plan

    def _start_pass(self, when: datetime) -> None:
        track = self.pass_track(when) or []
        self.plan = self._plan(track)
        self.flip_state = self.plan.flipped
        self._sent = None
        self.driver.stop_parking_timer()
        log.info("AOS: pass planned %s", "flipped" if self.plan.flipped else "normal")

    def _end_pass(self, when: datetime) -> None:
        self.plan = None
        if self.after_los == "park":
            params = self.driver.parking_parameters()
            if params.delay_minutes > 0:
                self.driver.start_parking_timer()
            else:
                self.driver.set_target(params.elevation_deg, params.azimuth_deg)
        elif self.after_los == "next-aos":
            track = self.pass_track(when + timedelta(seconds=1))
            if track:
                plan = self._plan(track)
                _, az, el = track[0]
                az_k, el_k = flip(az, el) if plan.flipped else (az, max(el, 0.0))
                self.driver.set_target(el_k, az_k)

    # -- per tick --------------------------------------------------------------------------
    def process(self, sample: TickSample) -> None:
        """One tick's work (the worker's step; tests call it directly)."""
        la = sample.look_angles
        if sample.tracking and la is not None:
            if sample.above_horizon:
                if self.plan is None:
                    self._start_pass(sample.time)
                az, el = self._aim(sample.time, la.azimuth_deg, la.elevation_deg)
                if self._sent is None or angular_distance(az, el, *self._sent) >= self.threshold_deg:
                    az_k, el_k = flip(az, el) if self.plan and self.plan.flipped else (az % 360.0, el)
                    if self.driver.set_target(el_k, az_k):
                        self._sent = (az, el)
            elif self.plan is not None:
                self._end_pass(sample.time)
        self.driver.service()
        pos = self.driver.rotor_position()
        if pos is not None and self.on_position is not None:
            self.on_position(*sky_from_rotor(*pos))

    def _aim(self, when: datetime, az: float, el: float) -> tuple[float, float]:
        """Where to point: the satellite's position one rotor travel time ahead."""
        pos = self.driver.rotor_position()
        if pos is None or self.max_lead_s == 0:
            return az, el
        travel = angular_distance(az, el, *sky_from_rotor(*pos)) / self.speed_deg_s
        lead = min(self.max_lead_s, travel)
        if lead < 0.5:
            return az, el
        ahead = self.predict(when + timedelta(seconds=lead))
        return ahead if ahead is not None else (az, el)

    def stop(self) -> None:
        super().stop()
        self.driver.backend.close()
