"""The one live station state that every output reads.

:class:`StationState` holds what the station *is* at this moment: the catalog, the observer, the
horizon table, UT1-UTC, the radio channels, the publish rate, and the session switches that
clients and the operator change (the AutoTracking satellite, the feed that Nova's ``TUNE`` switches
(``feed_on``: the Nova string is published), OrbitDRV's tracking and tuning enables (``tracking``, and
``doppler_on``: Doppler updates to the radio), the antenna position last reported).

Nothing else in the server keeps a copy of these values: the tracker, the DDE services, the
dialects, PREDICT, the rotor and radio couplings and the console read them from here each time they
need them, so a live configuration reload (:meth:`StationState.configure`) is seen by every output on
the next tick.

Threading: any thread may read or change the state; every change happens under one lock and bumps
:attr:`StationState.generation`, which readers use to invalidate derived caches.  Readers that need
several values consistent with each other take a :meth:`StationState.snapshot`.
"""

from __future__ import annotations

import threading
from collections.abc import Mapping
from dataclasses import dataclass, field
from datetime import datetime
from types import MappingProxyType

from nfwserver.channels.channel import Channel
from nfwserver.core.sample import AntennaPosition
from nfwserver.tracking.catalog import Catalog, Satellite
from nfwserver.tracking.horizon import HorizonTable
from nfwserver.tracking.observer import Observer

MIN_RATE_HZ, MAX_RATE_HZ, DEFAULT_RATE_HZ = 1.0, 50.0, 5.0


def check_rate(rate_hz: float) -> float:
    """The publish rate as a float; :class:`ValueError` outside 1..50 Hz."""
    rate = float(rate_hz)
    if not MIN_RATE_HZ <= rate <= MAX_RATE_HZ:
        raise ValueError(f"publish rate {rate_hz} Hz is outside {MIN_RATE_HZ:g}..{MAX_RATE_HZ:g} Hz")
    return rate


@dataclass(frozen=True)
class StateSnapshot:
    """A consistent view of :class:`StationState` at one instant (for one tick or one screen)."""

    generation: int
    catalog: Catalog
    observer: Observer | None
    horizon: HorizonTable
    ut1_utc_s: float
    rate_hz: float
    catalog_number: int | None
    satellite: Satellite | None  #: the AutoTracking satellite's record, None when unknown/none
    feed_on: bool  #: the feed: Nova's TUNE ON, the Nova string is published
    tracking: bool  #: OrbitDRV "tracking enabled": the rotor follows the satellite (Nova's TRACK ON)
    doppler_on: bool  #: OrbitDRV "tuning enabled": the radio receives Doppler updates
    antenna: AntennaPosition
    channels: Mapping[int, Channel] = field(default_factory=dict)
    #: who chose the selected satellite ("config", "saved-state", or the source of the command), read with it
    selected_by: str = ""


class StationState:
    """The live state; see the module docstring.  All setters return True when something changed."""

    def __init__(self, catalog: Catalog, observer: Observer | None, *, horizon: HorizonTable | None = None,
                 ut1_utc_s: float = 0.0, rate_hz: float = DEFAULT_RATE_HZ,
                 channels: Mapping[int, Channel] | None = None) -> None:
        self._lock = threading.RLock()
        self._catalog = catalog
        self._observer = observer
        self._horizon = horizon or HorizonTable()
        self._ut1_utc_s = float(ut1_utc_s)
        self._rate_hz = check_rate(rate_hz)
        self._channels: Mapping[int, Channel] = MappingProxyType(dict(channels or {}))
        self._selected_by = ""
        self._catalog_number: int | None = None
        self._feed_on = False
        self._tracking = False
        self._doppler_on = False
        self._antenna = AntennaPosition(None, None, "", None)
        self.generation = 0
        #: bumped when what passes depend on changes (elements, observer, horizon): a schedule is planned again
        self.sky_generation = 0

    # -- reading -----------------------------------------------------------------------------
    @property
    def catalog(self) -> Catalog:
        return self._catalog

    @property
    def observer(self) -> Observer | None:
        return self._observer

    @property
    def horizon(self) -> HorizonTable:
        return self._horizon

    @property
    def ut1_utc_s(self) -> float:
        return self._ut1_utc_s

    @property
    def rate_hz(self) -> float:
        return self._rate_hz

    @property
    def channels(self) -> Mapping[int, Channel]:
        return self._channels

    @property
    def catalog_number(self) -> int | None:
        return self._catalog_number

    @property
    def doppler_on(self) -> bool:
        return self._doppler_on

    @property
    def feed_on(self) -> bool:
        return self._feed_on

    def selected(self) -> Satellite | None:
        """The AutoTracking satellite's catalog record (None when none is selected or it is unknown)."""
        with self._lock:
            number = self._catalog_number
            return self._catalog.get(number) if number is not None else None

    def snapshot(self) -> StateSnapshot:
        with self._lock:
            return StateSnapshot(self.generation, self._catalog, self._observer, self._horizon, self._ut1_utc_s,
                                 self._rate_hz, self._catalog_number, self.selected(), self._feed_on,
                                 self._tracking, self._doppler_on, self._antenna, self._channels,
                                 self._selected_by)

    # -- changing ----------------------------------------------------------------------------
    def _set(self, name: str, value: object) -> bool:
        with self._lock:
            if getattr(self, name) == value:
                return False
            setattr(self, name, value)
            self.generation += 1
            return True

    def configure(self, *, observer: Observer | None, horizon: HorizonTable, ut1_utc_s: float, rate_hz: float,
                  channels: Mapping[int, Channel]) -> None:
        """Replace the station's configured values at once (start-up or a live reload)."""
        rate = check_rate(rate_hz)
        with self._lock:
            self._observer = observer
            self._horizon = horizon
            self._ut1_utc_s = float(ut1_utc_s)
            self._rate_hz = rate
            self._channels = MappingProxyType(dict(channels))
            self.generation += 1
            self.sky_generation += 1

    def select(self, catalog_number: int | None, by: str | None = None) -> bool:
        """Select ``catalog_number``; when that changes the selection, ``by`` (when given) records who chose it in
        the same step, so a reader never sees one satellite with another's chooser."""
        with self._lock:
            changed = self._set("_catalog_number", catalog_number)
            if changed and by is not None:
                self._selected_by = by
            return changed

    def set_selected_by(self, by: str) -> None:
        """Record who chose the current selection (a choice that selected what was already selected)."""
        with self._lock:
            self._selected_by = by

    def set_feed(self, on: bool) -> bool:
        """Nova's TUNE ON/OFF; True when it changed."""
        return self._set("_feed_on", bool(on))

    def set_tracking(self, on: bool) -> bool:
        return self._set("_tracking", bool(on))

    def set_doppler(self, on: bool) -> bool:
        """Doppler updates to the radio on or off (OrbitDRV's tuning enable); True when it changed."""
        return self._set("_doppler_on", bool(on))

    def catalog_changed(self) -> None:
        """Tell readers the catalog's contents changed (an element refresh updated it in place)."""
        with self._lock:
            self.generation += 1
            self.sky_generation += 1

    def report_antenna(self, azimuth_deg: float | None, elevation_deg: float | None, source: str,
                       when: datetime) -> None:
        """Record where the antennas point; None keeps that axis's previous value."""
        with self._lock:
            old = self._antenna
            self._antenna = AntennaPosition(old.azimuth_deg if azimuth_deg is None else azimuth_deg,
                                            old.elevation_deg if elevation_deg is None else elevation_deg,
                                            source, when)
