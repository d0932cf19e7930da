"""Look-ahead and pass tracks for autotracking, from the tracking engine and the live station state.

:class:`SatelliteTracks` gives :class:`nfwserver.rotor.coupling.RotorCoupling` the two callables it
needs for whichever satellite is selected now: ``predict(when)`` (sky az, el in degrees) and
``pass_track(when)`` (the pass in progress or the next one, sampled from max(AOS, when) to LOS).
It reads the observer, horizon, UT1-UTC and selection from :class:`~nfwserver.core.state.StationState`
on every call, so a live reload is followed at once; pass searches are cached per satellite, station
and pass.  Owned by the rotor worker thread.
"""

from __future__ import annotations

from datetime import datetime, timedelta

from nfwserver.core.state import StationState
from nfwserver.tracking.look_angles import LookAngleCalculator, PropagationError
from nfwserver.tracking.passes import Pass, find_passes


class SatelliteTracks:
    """Predictions for the satellite ``state`` has selected, from ``state``'s station."""

    def __init__(self, state: StationState, step_s: float = 10.0) -> None:
        self.state = state
        self.step_s = step_s
        self._calc: tuple[object, LookAngleCalculator] | None = None
        self._cache: tuple[object, Pass] | None = None

    def _current(self) -> tuple[object, LookAngleCalculator] | None:
        """(satrec, calculator) for the selection now, or None without a satellite or station."""
        snap = self.state.snapshot()
        if snap.satellite is None or snap.observer is None:
            return None
        key = (snap.observer, snap.ut1_utc_s)
        if self._calc is None or self._calc[0] != key:
            self._calc = (key, LookAngleCalculator(snap.observer, snap.ut1_utc_s))
        return snap.satellite.satrec, self._calc[1]

    def predict(self, when: datetime) -> tuple[float, float] | None:
        current = self._current()
        if current is None:
            return None
        satrec, calc = current
        try:
            la = calc.compute(satrec, when)
        except PropagationError:
            return None
        return la.azimuth_deg, la.elevation_deg

    def _pass_at(self, satrec: object, when: datetime) -> Pass | None:
        snap = self.state.snapshot()
        if snap.observer is None:
            return None
        key = (satrec, snap.observer, snap.horizon, snap.ut1_utc_s)
        if self._cache is not None and self._cache[0] == key:
            p = self._cache[1]
            if p.los is not None and p.los > when and (p.aos is None or p.aos - when < timedelta(hours=12)):
                return p
        passes = find_passes([satrec], snap.observer, when, when + timedelta(hours=36), horizon=snap.horizon,
                             ut1_utc=snap.ut1_utc_s)
        upcoming = next((p for p in passes if p.los is not None and p.los > when), None)
        if upcoming is not None:
            self._cache = (key, upcoming)
        return upcoming

    def pass_track(self, when: datetime) -> list[tuple[datetime, float, float]] | None:
        current = self._current()
        if current is None:
            return None
        satrec, calc = current
        p = self._pass_at(satrec, when)
        if p is None or p.los is None:
            return None
        t = max(p.aos or when, when)
        track = []
        while t <= p.los:
            la = calc.compute(satrec, t)
            track.append((t, la.azimuth_deg, la.elevation_deg))
            t += timedelta(seconds=self.step_s)
        la = calc.compute(satrec, p.los)
        track.append((p.los, la.azimuth_deg, la.elevation_deg))
        return track
