"""Which satellites' positions can be trusted at an instant (InstantTrack's OLD and CRASH checks).

A satellite is *unusable* at ``at`` when SGP4 cannot propagate its set there (decayed, or an
orbit the model refuses) or when the result is implausibly far from the observer: no object in
an SGP4 catalog (Earth orbits) is further than :data:`MAX_PLAUSIBLE_RANGE_KM` (1.5 million km,
about four times the Moon's distance), so a larger range is a set propagated far outside its
validity.  A set is *stale* when its epoch lies more
than ``max_age_days`` (30 by default) before ``at``; stale sets are still used, with a warning.
"""

from __future__ import annotations

from collections.abc import Sequence
from datetime import datetime
from typing import Any

import numpy as np
import numpy.typing as npt

from nfwserver.tracking.look_angles import look_angles_array
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.pass_events import MAX_PLAUSIBLE_RANGE_KM
from nfwserver.tracking.staleness import STALE_AFTER_DAYS, stale_satellites
from nfwserver.tracking.timescale import julian_date

__all__ = ["MAX_PLAUSIBLE_RANGE_KM", "STALE_AFTER_DAYS", "stale_satellites",
           "usable_mask", "usable_models"]
#: Satellites propagated at a time by :func:`usable_mask` (bounds the SGP4 models held at once).
_BLOCK = 512


def usable_mask(satellites: Sequence[Any], observer: Observer, at: datetime, ut1_utc: float = 0.0,
                max_range_km: float = MAX_PLAUSIBLE_RANGE_KM) -> npt.NDArray[np.bool_]:
    """True for each of ``satellites`` whose position at ``at`` is usable (see the module docstring).

    Element sets (objects with ``transient_satrec``, also inside a satellite's ``elements``) are propagated
    with models made for this check and dropped, a block at a time, so a whole catalog is checked
    without keeping a model for every set.
    """
    good = np.zeros(len(satellites), dtype=bool)
    jd, fr = julian_date(at)
    for b0 in range(0, len(satellites), _BLOCK):
        models = [_model(s) for s in satellites[b0 : b0 + _BLOCK]]
        good[b0 : b0 + len(models)] = usable_models(models, observer, jd, fr, ut1_utc, max_range_km)
    return good


def usable_models(models: Sequence[Any], observer: Observer, jd: float, fr: float, ut1_utc: float = 0.0,
                  max_range_km: float = MAX_PLAUSIBLE_RANGE_KM) -> npt.NDArray[np.bool_]:
    """True for each SGP4 model (``sgp4`` Satrec) whose position at the UTC Julian date ``jd + fr`` is usable
    (see the module docstring)."""
    arr = look_angles_array(list(models), observer, np.array([jd]), np.array([fr]), ut1_utc)
    rng = arr.range_km[:, 0]
    with np.errstate(invalid="ignore"):
        usable: npt.NDArray[np.bool_] = np.isfinite(rng) & (rng <= max_range_km) & np.isfinite(arr.elevation_deg[:, 0])
    return usable


def _model(satellite: Any) -> Any:
    """An SGP4 model of ``satellite``: its element set's transient one when it has an element set, else its
    ``.satrec``."""
    elements = getattr(satellite, "elements", satellite)
    transient = getattr(elements, "transient_satrec", None)
    return transient() if transient is not None else satellite.satrec
