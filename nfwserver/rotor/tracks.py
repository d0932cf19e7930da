"""Look-ahead and pass tracks for autotracking, from the tracking engine.

:class:`SatelliteTracks` gives :class:`nfwserver.rotor.coupling.RotorCoupling` the two callables it
needs for whichever satellite is selected now: ``predict(when)`` (sky az, el) and
``pass_track(when)`` (the pass in progress or the next one, sampled from max(AOS, when) to LOS).
Pass searches are cached per satellite and pass.
"""

from __future__ import annotations

from collections.abc import Callable
from datetime import datetime, timedelta

from nfwserver.tracking.horizon import HorizonTable
from nfwserver.tracking.look_angles import LookAngleCalculator, PropagationError
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.passes import Pass, find_passes


class SatelliteTracks:
    """``satrec_now()`` returns the selected satellite's SGP4 model (or None)."""

    def __init__(self, satrec_now: Callable[[], object | None], observer: Observer,
                 horizon: HorizonTable | None = None, ut1_utc: float = 0.0, step_s: float = 10.0) -> None:
        self.satrec_now = satrec_now
        self.observer = observer
        self.horizon = horizon or HorizonTable()
        self.ut1_utc = ut1_utc
        self.step_s = step_s
        self._calc = LookAngleCalculator(observer, ut1_utc)
        self._cache: tuple[object, Pass] | None = None

    def predict(self, when: datetime) -> tuple[float, float] | None:
        satrec = self.satrec_now()
        if satrec is None:
            return None
        try:
            la = self._calc.compute(satrec, when)
        except PropagationError:
            return None
        return la.azimuth_deg, la.elevation_deg

    def _pass_at(self, satrec: object, when: datetime) -> Pass | None:
        if self._cache is not None and self._cache[0] is satrec:
            p = self._cache[1]
            if p.los is not None and p.los > when and (p.aos is None or p.aos - when < timedelta(hours=12)):
                return p
        passes = find_passes([satrec], self.observer, when, when + timedelta(hours=36), horizon=self.horizon,
                             ut1_utc=self.ut1_utc)
        upcoming = next((p for p in passes if p.los is not None and p.los > when), None)
        if upcoming is not None:
            self._cache = (satrec, upcoming)
        return upcoming

    def pass_track(self, when: datetime) -> list[tuple[datetime, float, float]] | None:
        satrec = self.satrec_now()
        if satrec is None:
            return None
        p = self._pass_at(satrec, when)
        if p is None or p.los is None:
            return None
        t = max(p.aos or when, when)
        track = []
        while t <= p.los:
            la = self._calc.compute(satrec, t)
            track.append((t, la.azimuth_deg, la.elevation_deg))
            t += timedelta(seconds=self.step_s)
        la = self._calc.compute(satrec, p.los)
        track.append((p.los, la.azimuth_deg, la.elevation_deg))
        return track
