"""The satellite catalog: element sets keyed by catalog number, with update semantics and DDE names.

:meth:`Catalog.update` follows InstantTrack's UPDATE: a set replaces the stored one only when
its epoch is newer; new satellites are added.  Each satellite has a unique DDE name
(:mod:`nfwserver.tracking.dde_names`); user overrides win.  DDE names are assigned when first needed
(a reader asking for a :class:`Satellite`): a catalog used only for its element sets (a pass search
over tens of thousands of objects) never pays for them.

Threading: any number of readers and writers.  Writers (:meth:`Catalog.update`,
:meth:`Catalog.set_dde_name`) take turns on a writer lock and do all their work -- merging and, once
readers have asked for names, naming every satellite (about 6 us each) -- on their own thread, holding
no lock a reader needs; they publish the result by swapping references under the reader lock.  A
reader (the publish thread's tick) therefore never waits for a merge or a naming, however large the
catalog; an update that changes nothing swaps nothing.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from datetime import datetime

from sgp4.api import Satrec

from nfwserver.tracking.constants import SECONDS_PER_DAY, WGS72_A_KM, WGS72_MU_KM3_S2
from nfwserver.tracking.dde_names import assign_dde_names, validate_dde_name
from nfwserver.tracking.elements import ElementSet


@dataclass(frozen=True)
class Satellite:
    """A catalog entry: the current element set and the satellite's DDE name."""

    elements: ElementSet
    dde_name: str

    @property
    def catalog_number(self) -> int:
        return self.elements.catalog_number

    @property
    def name(self) -> str:
        return self.elements.name

    @property
    def satrec(self) -> Satrec:
        return self.elements.satrec

    def age_days(self, at: datetime) -> float:
        """Element age at ``at``: days since the epoch (negative before it)."""
        return (at - self.elements.epoch).total_seconds() / SECONDS_PER_DAY

    @property
    def perigee_height_km(self) -> float:
        """Perigee height above the equatorial radius (km), from the mean motion (WGS72)."""
        n = self.elements.mean_motion_rev_per_day * 2.0 * math.pi / SECONDS_PER_DAY
        a = (WGS72_MU_KM3_S2 / (n * n)) ** (1.0 / 3.0)
        return float(a * (1.0 - self.elements.eccentricity) - WGS72_A_KM)

    @property
    def is_decayed(self) -> bool:
        """True when the mean perigee lies below the Earth's surface."""
        return self.perigee_height_km < 0.0


@dataclass(frozen=True)
class UpdateSummary:
    """Catalog numbers added, replaced (newer epoch), and left alone (not newer)."""

    added: list[int] = field(default_factory=list)
    updated: list[int] = field(default_factory=list)
    not_newer: list[int] = field(default_factory=list)


class Catalog:
    """Satellites by catalog number."""

    def __init__(self, sets: Iterable[ElementSet] = (), dde_names: dict[int, str] | None = None) -> None:
        self._lock = threading.Lock()  #: readers: held only to swap, or to name lazily the first time
        self._write_lock = threading.Lock()  #: writers take turns, holding it through their work
        self._elements: dict[int, ElementSet] = {}
        self._overrides: dict[int, str] = {}
        #: satellites with their DDE names, made on first use from ``_elements`` (None: not made yet)
        self._satellites: dict[int, Satellite] | None = None
        for catnr, name in (dde_names or {}).items():
            self._overrides[int(catnr)] = validate_dde_name(name)
        self.update(sets)

    def update(self, sets: Iterable[ElementSet]) -> UpdateSummary:
        """Merge ``sets``: add unknown satellites, replace a set only by a newer epoch.

        Runs on the caller's thread (see the module docstring); readers see the previous catalog until
        the new one, names included, is swapped in."""
        summary = UpdateSummary()
        with self._write_lock:
            elements = dict(self._elements)
            for es in sets:
                old = elements.get(es.catalog_number)
                if old is None:
                    summary.added.append(es.catalog_number)
                elif es.epoch > old.epoch:
                    summary.updated.append(es.catalog_number)
                else:
                    summary.not_newer.append(es.catalog_number)
                    continue
                elements[es.catalog_number] = es
            if summary.added or summary.updated:
                self._swap(elements, self._overrides)
        return summary

    def _swap(self, elements: dict[int, ElementSet], overrides: dict[int, str]) -> None:
        """Publish ``elements`` and ``overrides`` (the caller holds the writer lock).  Once readers have
        asked for names, the new names are made here, before the swap, so that no reader makes them."""
        satellites = self._make_satellites(elements, overrides) if self._satellites is not None else None
        with self._lock:
            old = self._elements, self._satellites
            self._elements, self._overrides, self._satellites = elements, overrides, satellites
        # A published table is never changed: a reader may still be reading the old one, and the new one may be
        # the old one (a new name keeps the element sets).  The old entries are released one at a time from a
        # list of their own, since a whole catalog freed at once holds the interpreter lock for 20-40 ms; a
        # reader still holding an old table keeps it whole.
        leftovers = [list(table.values()) for table in old if table is not None and table is not elements]
        del old
        for entries in leftovers:
            while entries:
                entries.pop()

    @staticmethod
    def _make_satellites(elements: dict[int, ElementSet], overrides: dict[int, str]) -> dict[int, Satellite]:
        names = assign_dde_names({k: v.name for k, v in elements.items()},
                                 {k: v for k, v in overrides.items() if k in elements})
        return {k: Satellite(elements[k], names[k]) for k in sorted(elements)}

    def _named(self) -> dict[int, Satellite]:
        """The satellites with their DDE names, made now by the first reader that needs them; from then
        on writers make them before they swap."""
        satellites = self._satellites
        if satellites is None:
            with self._lock:
                satellites = self._satellites
                if satellites is None:
                    satellites = self._satellites = self._make_satellites(self._elements, self._overrides)
        return satellites

    def set_dde_name(self, catalog_number: int, name: str) -> None:
        """Override the DDE name of a satellite (may be set before its elements arrive).

        Raises :class:`ValueError` for an unusable name or one held by another override.
        """
        validate_dde_name(name)
        with self._write_lock:
            for other, held in self._overrides.items():
                if other != catalog_number and held.upper() == name.upper():
                    raise ValueError(f"DDE name {name!r} is already given to satellite {other}")
            if self._overrides.get(catalog_number) != name:
                self._swap(self._elements, {**self._overrides, catalog_number: name})

    def get(self, catalog_number: int) -> Satellite | None:
        return self._named().get(catalog_number)

    def dde_names_of(self, catalog_numbers: Iterable[int]) -> list[str]:
        """The DDE names of ``catalog_numbers`` (the number itself for one not in the catalog).  Until a reader
        has asked for satellites, the names are made for this call and not kept (a command naming a few
        satellites of a large catalog keeps no name for the others)."""
        satellites = self._satellites
        if satellites is not None:
            return [sat.dde_name if (sat := satellites.get(n)) is not None else str(n) for n in catalog_numbers]
        with self._lock:
            elements, overrides = self._elements, self._overrides
        names = assign_dde_names({k: v.name for k, v in elements.items()},
                                 {k: v for k, v in overrides.items() if k in elements})
        return [names.get(n, str(n)) for n in catalog_numbers]

    def named(self, name: str) -> list[Satellite]:
        """The satellites whose DDE name or element-set name is ``name`` (case ignored), as ``SAT=`` matches."""
        key = name.strip().upper()
        return [s for s in self if key in (s.dde_name.upper(), s.name.upper())]

    def __contains__(self, catalog_number: object) -> bool:
        return catalog_number in self._elements

    def __len__(self) -> int:
        return len(self._elements)

    def __iter__(self) -> Iterator[Satellite]:
        return iter(list(self._named().values()))

    def satellites(self) -> list[Satellite]:
        """All satellites, ascending catalog number."""
        return list(self._named().values())

    def element_sets(self) -> list[ElementSet]:
        """Every satellite's element set, ascending catalog number (no DDE names are made)."""
        elements = self._elements
        return [elements[k] for k in sorted(elements)]

    def find(self, text: str) -> Satellite | None:
        """A satellite by catalog number, DDE name or element name (case-insensitive)."""
        text = text.strip()
        if text.isdigit():
            return self.get(int(text))
        key = text.upper()
        sats = self._named().values()
        for sat in sats:
            if sat.dde_name.upper() == key:
                return sat
        for sat in sats:
            if sat.name.upper() == key:
                return sat
        return None
