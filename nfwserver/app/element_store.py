"""The stored element catalog: what ``nfwserver elements update`` keeps between runs.

One text file of 3-line TLEs (canonical lines, so every format that was loaded is stored the same
way) in the platform's user data directory.  Updates follow InstantTrack's UPDATE rule (a set
replaces the stored one only when its epoch is newer) and are written atomically: a crash during
an update leaves the previous file whole, and the temporary it leaves is removed the next time a
store is opened on that file (:func:`nfwserver.storage.remove_stale_temporaries`).  Every read-modify-write
holds the store's lock (:mod:`nfwserver.file_lock`), so parallel updates lose nothing.  The stored file
keeps its permissions across updates.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from datetime import datetime, timedelta
from pathlib import Path

from sgp4.api import jday

from nfwserver.file_lock import locked
from nfwserver.storage import atomic_write_text, remove_stale_temporaries
from nfwserver.tracking.catalog import Catalog, UpdateSummary
from nfwserver.tracking.elements import ElementSet, load_element_file

log = logging.getLogger(__name__)


def default_store_path() -> Path:
    from platformdirs import user_data_dir

    return Path(user_data_dir("nfwserver", appauthor=False)) / "elements.txt"


@dataclass
class PruneSummary:
    """What :meth:`ElementStore.plan_prune` would remove and what stays."""

    decayed: list[ElementSet] = field(default_factory=list)  #: InstantTrack's CRASH
    old: list[ElementSet] = field(default_factory=list)  #: InstantTrack's OLD
    kept: int = 0
    protected: list[ElementSet] = field(default_factory=list)  #: old or decayed, kept because asked to

    @property
    def removed(self) -> list[ElementSet]:
        return [*self.decayed, *self.old]

    @property
    def total(self) -> int:
        """Sets in the store when planned."""
        return self.kept + len(self.removed)


def has_decayed(es: ElementSet, at: datetime) -> bool:
    """True when the object has come down by ``at``: mean perigee below the surface, or SGP4
    refusing to propagate the set to ``at`` (its decay and eccentricity checks)."""
    jd, fr = jday(at.year, at.month, at.day, at.hour, at.minute, at.second + at.microsecond / 1e6)
    error, _, _ = es.satrec.sgp4(jd, fr)
    if error != 0:
        return True
    from nfwserver.tracking.catalog import Satellite

    return Satellite(es, "").is_decayed


class ElementStore:
    """The stored catalog at ``path``."""

    def __init__(self, path: str | Path | None = None) -> None:
        self.path = Path(path) if path is not None else default_store_path()
        for stale in remove_stale_temporaries(self.path):
            log.info("removed %s, left by an interrupted update", stale.name)

    def load(self) -> list[ElementSet]:
        """The stored sets (none if the file does not exist yet)."""
        if not self.path.exists():
            return []
        return load_element_file(self.path).sets

    def update(self, sets: list[ElementSet]) -> tuple[Catalog, UpdateSummary]:
        """Merge ``sets`` into the stored catalog with UPDATE semantics and write it atomically, reading and
        writing under the store's lock (another ``elements update``, a running station's refresher)."""
        with locked(self.path):
            catalog = Catalog(self.load())
            summary = catalog.update(sets)
            if summary.added or summary.updated or not self.path.exists():
                text = "".join(es.tle_text() for es in catalog.element_sets())
                atomic_write_text(self.path, text)
        return catalog, summary

    def plan_prune(self, now: datetime, max_age_days: float, keep: frozenset[int] = frozenset()) -> PruneSummary:
        """What pruning would remove: decayed objects and sets whose epoch is more than ``max_age_days`` before
        ``now``, except the catalog numbers in ``keep`` (the selected satellite, favourites).  Writes nothing."""
        summary = PruneSummary()
        oldest = now - timedelta(days=max_age_days)
        for es in self.load():
            doomed = summary.decayed if has_decayed(es, now) else summary.old if es.epoch < oldest else None
            if doomed is None:
                summary.kept += 1
            elif es.catalog_number in keep:
                summary.protected.append(es)
                summary.kept += 1
            else:
                doomed.append(es)
        return summary

    def apply_prune(self, planned: PruneSummary) -> int:
        """Remove exactly the sets ``planned`` names (same catalog number and epoch; a set updated since
        the plan stays) and rewrite the file atomically if anything went; returns how many sets remain."""
        gone = {(es.catalog_number, es.epoch) for es in planned.removed}
        with locked(self.path):
            sets = self.load()
            kept = [es for es in sets if (es.catalog_number, es.epoch) not in gone]
            if len(kept) != len(sets):
                atomic_write_text(self.path, "".join(es.tle_text() for es in kept))
        return len(kept)
