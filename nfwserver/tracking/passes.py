"""Pass prediction: AOS, TCA, LOS against a horizon table, for one satellite or whole catalogs.

A pass is an interval during which the satellite's elevation is above the horizon table's minimum
elevation at its azimuth (:mod:`nfwserver.tracking.horizon`): AOS is the upward crossing, LOS the
downward one, TCA the instant of maximum elevation in between.  Times are aware UTC datetimes,
angles degrees.

The search runs in three stages, each batched over every satellite of the catalog:

1. :mod:`~nfwserver.tracking.pass_screen`: a coarse grid proves most of the time invisible and
   brackets every crossing, every possible hidden short pass and every culmination;
2. :mod:`~nfwserver.tracking.pass_refine`: safeguarded iteration with analytic derivatives
   (second-order steps for crossings, Newton steps for maxima) refines the brackets of every
   satellite together (crossings to 0.1 ms, maxima to 1 ms);
3. :mod:`~nfwserver.tracking.pass_assemble`: crossings first, then the culminations from the
   middle of their pass; rises and sets are paired into passes and each pass gets its TCA.

Satellites are searched in groups of similar orbits (low, geosynchronous-like, the rest), each
with its own grid step and look-back, a chunk of 200 at a time; the brackets of several chunks are
refined together (:mod:`~nfwserver.tracking.pass_batch`), each satellite against its own chunk's
reference instant, which gives the passes of refining every chunk alone, bit for bit, in fewer rounds.
Passes already in progress at ``start`` are reported with
their true AOS before ``start`` (``aos_before_start``), passes in progress at ``end`` with their
LOS after it: the search looks back and ahead by up to one orbital period (at most a day; half a
period for near-circular orbits shorter than three hours, whose passes last less than that).  A
satellite that stays up over the whole extended search (a geostationary satellite in view, say) gets
one pass with neither AOS nor LOS (``None``: both beyond the search), whose TCA is the highest point
inside the window (:mod:`~nfwserver.tracking.pass_always_up`), rather than no pass or bogus events; one
whose rise or set lies beyond the extension gets ``None`` for that time.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from datetime import datetime, timedelta, timezone
from typing import Any

import numpy as np

from nfwserver.forked_children import can_fork
from nfwserver.tracking.constants import MINUTES_PER_DAY
from nfwserver.tracking.frames import TopocentricFrame
from nfwserver.tracking.horizon import HorizonTable
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.pass_always_up import always_up_columns
from nfwserver.tracking.pass_assemble import assemble
from nfwserver.tracking.pass_batch import Batch, Chunk
from nfwserver.tracking.pass_events import MAX_LOOK_BACK_S, NEAR_CIRCULAR_ECC, SHORT_PERIOD_S, look_back_s
from nfwserver.tracking.pass_kinematics import PairEvaluator
from nfwserver.tracking.pass_records import Pass, PassColumns, PassList
from nfwserver.tracking.pass_screen import screen
from nfwserver.tracking.pass_spill import SpilledPasses
from nfwserver.tracking.pass_workers import in_forked_workers
from nfwserver.tracking.screening import usable_models
from nfwserver.tracking.timescale import julian_date

__all__ = ["Pass", "PassList", "SpilledPasses", "find_passes", "find_passes_spilled"]

_FLAT = HorizonTable()
#: Mean motion (rev/day) below which a near-circular orbit joins the geosynchronous-like group.
_SLOW_REV_PER_DAY = 1.5
#: Coarse grid steps (s) of the three groups: low, geosynchronous-like, the rest.
_LOW_STEP_S, _SLOW_STEP_S, _OTHER_STEP_S = 1200.0, 3600.0, 1200.0
#: Satellites screened together (bounds the memory of one screen).
_CHUNK = 200
#: Brackets refined together (at least; a batch takes whole chunks): bounds the memory of one refinement.
_BATCH_BRACKETS = 10000


def find_passes(
    satellites: Sequence[Any],
    observer: Observer,
    start: datetime,
    end: datetime,
    horizon: HorizonTable | None = None,
    ut1_utc: float = 0.0,
    fine_step_s: float = 60.0,
    workers: int = 1,
) -> PassList:
    """Passes of ``satellites`` between ``start`` and ``end``: element sets (whose SGP4 models are made for the
    search and dropped unless they exist), catalog satellites (their element sets), ``sgp4`` Satrecs or objects
    with a ``.satrec``.

    Returns the passes overlapping the window, sorted by AOS (TCA when AOS is unknown), as a
    :class:`~nfwserver.tracking.pass_records.PassList` (a read-only sequence of :class:`Pass`).  See the
    module docstring for the method and for passes cut by the window.  Satellites whose positions at
    ``start`` cannot be computed or are implausibly far (:mod:`~nfwserver.tracking.screening`: decayed, or
    elements far outside their validity) are left out and listed in the result's ``skipped``.

    ``fine_step_s`` is the sampling step for low eccentric orbits and under non-flat horizons; slower
    satellites are sampled proportionally more coarsely.

    ``workers`` > 1 splits large catalogs over that many forked processes (POSIX only; meant for
    command-line use), each searching whole chunks of the one-process search.  Forking a process that runs
    other threads can deadlock the child, so the work stays in this process unless it is single-threaded.
    The passes found are those of one process, bit for bit.
    """
    found = _find(satellites, observer, start, end, horizon, ut1_utc, fine_step_s, workers, False)
    assert isinstance(found, PassList)
    return found


def find_passes_spilled(
    satellites: Sequence[Any],
    observer: Observer,
    start: datetime,
    end: datetime,
    horizon: HorizonTable | None = None,
    ut1_utc: float = 0.0,
    fine_step_s: float = 60.0,
    workers: int = 1,
) -> SpilledPasses:
    """The passes :func:`find_passes` finds, kept in temporary files and read back in order a slab at a time
    (:class:`~nfwserver.tracking.pass_spill.SpilledPasses`): for writing a large search's passes out without
    holding them all.  The caller closes the result (deleting the files)."""
    found = _find(satellites, observer, start, end, horizon, ut1_utc, fine_step_s, workers, True)
    assert isinstance(found, SpilledPasses)
    return found


def _find(satellites: Sequence[Any], observer: Observer, start: datetime, end: datetime, horizon: HorizonTable | None,
          ut1_utc: float, fine_step_s: float, workers: int, spilled: bool) -> PassList | SpilledPasses:
    """:func:`find_passes`, or with ``spilled`` :func:`find_passes_spilled`."""
    satellites = [getattr(s, "elements", s) for s in satellites]  # a catalog satellite's element set
    horizon = horizon or _FLAT
    if start.tzinfo is None:
        start = start.replace(tzinfo=timezone.utc)
    if end.tzinfo is None:
        end = end.replace(tzinfo=timezone.utc)
    window_s = (end - start).total_seconds()
    if end <= start or not satellites:
        return SpilledPasses(start, max(window_s, 0.0)).seal() if spilled else PassList(start, max(window_s, 0.0))
    plan = _plan(satellites, window_s)
    args = (observer, start, end, horizon, ut1_utc, fine_step_s)
    if workers > 1 and len(plan) > 1 and can_fork():
        workers = min(workers, len(plan))
        if not spilled:
            return PassList.concat(start, window_s, in_forked_workers(_search, satellites, plan, args, workers))
        import tempfile

        spills = [tempfile.TemporaryFile() for _ in range(workers)]  # noqa: SIM115 (closed by the result)
        try:
            parts = in_forked_workers(_search, satellites, plan, args, workers, spills)
        except BaseException:
            for spill in spills:
                spill.close()
            raise
        return SpilledPasses.joined(start, window_s, spills, parts)
    into = SpilledPasses(start, window_s) if spilled else None
    return _search(satellites, plan, sum(c.room for c in plan), *args, into)


@dataclass(frozen=True)
class _Chunk:
    """Satellites searched together (indices into the search's list, and their catalog numbers), their coarse
    step (s), how far the search looks back and ahead (s), and room for their passes (rows)."""

    members: np.ndarray
    catalog_numbers: np.ndarray
    step_s: float
    extension_s: float
    room: int


def _plan(satellites: Sequence[Any], window_s: float) -> list[_Chunk]:
    """The chunks of a search, which alone decide its passes: satellites are grouped by orbit, sorted by
    look-back, and cut into chunks of ``_CHUNK``."""
    no, ecc, catalog_numbers = _orbits(satellites)
    periods = 2.0 * math.pi / np.maximum(no, 1e-9) * 60.0  # s
    rev_per_day = no * MINUTES_PER_DAY / (2.0 * math.pi)
    short = periods <= SHORT_PERIOD_S  # the low group
    slow = ~short & (rev_per_day < _SLOW_REV_PER_DAY) & (ecc < NEAR_CIRCULAR_ECC)
    other = ~short & ~slow
    look_back = np.array([look_back_s(p, e) for p, e in zip(periods.tolist(), ecc.tolist())])  # s
    # Room for every pass there can be over a flat horizon (one per orbit in the searched span, plus the
    # first); an obstructed horizon can split passes, and then the columns grow.
    room = np.ceil((window_s + 2.0 * np.minimum(look_back, MAX_LOOK_BACK_S)) / periods) + 1.0
    plan = []
    # The rest is split by period so that each part looks back and ahead only as far as it needs.
    for group, step in ((short, _LOW_STEP_S), (slow, _SLOW_STEP_S), (other & (periods <= 8 * 3600.0), _OTHER_STEP_S),
                        (other & (periods > 8 * 3600.0) & (periods <= 13 * 3600.0), _OTHER_STEP_S),
                        (other & (periods > 13 * 3600.0), _OTHER_STEP_S)):
        members = np.flatnonzero(group)
        # Chunks of similar look-back, so that one eccentric orbit does not lengthen its chunk-mates' search.
        members = members[np.argsort(look_back[members], kind="stable")]
        for c0 in range(0, len(members), _CHUNK):
            idx = members[c0 : c0 + _CHUNK]
            plan.append(_Chunk(idx, catalog_numbers[idx], step, float(min(np.max(look_back[idx]), MAX_LOOK_BACK_S)),
                               int(np.sum(room[idx]))))
    return plan


def _search(satellites: Sequence[Any], chunks: Iterable[_Chunk], room: int, observer: Observer, start: datetime,
            end: datetime, horizon: HorizonTable, ut1_utc: float, fine_step_s: float,
            spill: SpilledPasses | None = None) -> PassList | SpilledPasses:
    """The passes of ``chunks`` (aware ``start`` and ``end``), in this process (into ``spill`` when given; else
    into columns with ``room`` rows to start with)."""
    window_s = (end - start).total_seconds()
    found = spill if spill is not None else PassColumns(room)
    batch = Batch()
    jd_start, fr_start = julian_date(start)
    skipped: list[int] = []
    for chunk in chunks:
        numbers = chunk.catalog_numbers
        models = [_model(satellites[i]) for i in chunk.members.tolist()]
        usable = usable_models(models, observer, jd_start, fr_start, ut1_utc)
        if not usable.all():  # the check every caller would make, on the models made here anyway
            skipped += numbers[~usable].tolist()
            models = [m for m, ok in zip(models, usable.tolist()) if ok]
            numbers = numbers[usable]
            if not models:
                continue
        screened, always_up = _screen_chunk(models, numbers, observer, start, end, horizon, ut1_utc, fine_step_s,
                                            chunk.step_s, chunk.extension_s)
        batch.add(screened)
        found.add(always_up)
        if batch.size >= _BATCH_BRACKETS:
            found.add(_refine(batch, observer, horizon, ut1_utc))
            batch = Batch()
    if batch.chunks:
        found.add(_refine(batch, observer, horizon, ut1_utc))
    if isinstance(found, SpilledPasses):
        return found.seal(skipped)
    return found.pass_list(start, window_s, skipped)


def _orbits(satellites: Sequence[Any]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mean motion (rad/min, SGP4's ``no_kozai``), eccentricity and catalog number of every satellite, read
    from an :class:`~nfwserver.tracking.elements.ElementSet`'s fields without making its SGP4 model."""
    if all(hasattr(s, "mean_motion_rev_per_day") for s in satellites):
        return (np.array([s.mean_motion_rev_per_day for s in satellites]) / (MINUTES_PER_DAY / (2.0 * math.pi)),
                np.array([s.eccentricity for s in satellites]),
                np.array([s.catalog_number for s in satellites], dtype=np.int64))
    satrecs = [getattr(s, "satrec", s) for s in satellites]
    return (np.array([sr.no_kozai for sr in satrecs]), np.array([sr.ecco for sr in satrecs]),
            np.array([int(sr.satnum) for sr in satrecs], dtype=np.int64))


def _model(satellite: object) -> object:
    """The SGP4 model of ``satellite`` (an ``sgp4`` Satrec, or an object with a ``.satrec``), made only for
    this search when the object can make one without keeping it (ElementSet.transient_satrec)."""
    transient = getattr(satellite, "transient_satrec", None)
    return transient() if transient is not None else getattr(satellite, "satrec", satellite)


def _screen_chunk(satrecs: list[Any], catalog_numbers: np.ndarray, observer: Observer, start: datetime, end: datetime,
                  horizon: HorizonTable, ut1_utc: float, fine_step_s: float, coarse_step_s: float,
                  extension: float) -> tuple[Chunk, dict[str, np.ndarray]]:
    """One chunk of satellites screened over ``[start - extension, end + extension]``, and the passes of those
    above the horizon throughout (PassList columns)."""
    t0 = start - timedelta(seconds=extension)
    window_s = (end - start).total_seconds()
    span = window_s + 2.0 * extension
    jd0, fr0 = julian_date(t0)
    ev = PairEvaluator(satrecs, observer, jd0, fr0, ut1_utc, horizon)
    brackets = screen(satrecs, TopocentricFrame(observer), horizon, jd0, fr0, span, coarse_step_s, fine_step_s,
                      ut1_utc, ev)
    always_up = always_up_columns(ev, brackets, len(satrecs), catalog_numbers, extension, window_s)
    return Chunk(satrecs, catalog_numbers, jd0, fr0, span, extension, extension + window_s, brackets), always_up


def _refine(batch: Batch, observer: Observer, horizon: HorizonTable, ut1_utc: float) -> dict[str, np.ndarray]:
    """Passes (PassList columns, times after the window start) from the brackets of a batch of chunks."""
    models, jd0, fr0, layout, brackets = batch.merged()
    ev = PairEvaluator(models, observer, jd0, fr0, ut1_utc, horizon)
    return assemble(ev, brackets, horizon.is_flat, layout)
