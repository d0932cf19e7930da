"""Pass search over several chunks of satellites at once: each chunk screened on its own span, refined together.

A catalog is searched in chunks of similar orbits (:mod:`nfwserver.tracking.passes`), each with its own
coarse step and look-back, so each chunk has its own search span and reference instant (the start of
its span).  Screening (:mod:`~nfwserver.tracking.pass_screen`) is done chunk by chunk, but refinement
(:mod:`~nfwserver.tracking.pass_refine`) costs a fixed ~0.1 ms of numpy work per round however few
brackets a round holds, so the brackets of several chunks are gathered into one :class:`Batch` and
refined together, every satellite keeping its chunk's reference instant and window.  Each bracket's
arithmetic is the same as when its chunk is searched alone, so the passes found are identical.

Times are seconds after each satellite's own reference instant (the start of its chunk's span).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from nfwserver.tracking.pass_records import distinct
from nfwserver.tracking.pass_screen import Brackets, Intervals

#: Key spacing per satellite when sorting (sat, t) pairs as one float (s; far above any span).
KEY_SPACING = 1e8


@dataclass
class Layout:
    """Per satellite of a batch (arrays indexed by the batch's satellite index): catalog number, search span
    (s), window start and end (s after the satellite's reference instant); and where each chunk starts."""

    catalog_numbers: np.ndarray
    span: np.ndarray
    win_lo: np.ndarray
    win_hi: np.ndarray
    chunk_starts: np.ndarray  #: batch index of each chunk's first satellite, ascending (starts at 0)

    def keys(self, sat: np.ndarray, t: np.ndarray) -> np.ndarray:
        """``sat * KEY_SPACING + t`` with each satellite's index within its chunk: sortable (sat, t) keys of
        one chunk, rounded exactly as a search of that chunk alone rounds them."""
        first = self.chunk_starts[np.searchsorted(self.chunk_starts, sat, side="right") - 1]
        keys: np.ndarray = (sat - first) * KEY_SPACING + t
        return keys

    def search(self, key_sat: np.ndarray, keys: np.ndarray, q_sat: np.ndarray, q_keys: np.ndarray,
               side: Literal["left", "right"]) -> np.ndarray:
        """``np.searchsorted`` of the queries among ``keys`` (of pairs sorted by satellite, then time), each
        query among the keys of its own chunk (positions into the whole of ``keys``)."""
        out = np.empty(len(q_keys), dtype=np.intp)
        bounds = np.searchsorted(key_sat, self.chunk_starts).tolist() + [len(keys)]
        q_chunk = np.searchsorted(self.chunk_starts, q_sat, side="right") - 1
        for c in distinct(q_chunk).tolist():
            mine = q_chunk == c
            lo, hi = bounds[c], bounds[c + 1]
            out[mine] = lo + np.searchsorted(keys[lo:hi], q_keys[mine], side=side)
        return out


@dataclass
class Chunk:
    """One chunk's satellites (SGP4 models, catalog numbers), its reference instant (split UTC Julian date),
    span and window (s after the reference instant), and the brackets its screen found (chunk indices)."""

    models: list[Any]
    catalog_numbers: np.ndarray
    jd0: float
    fr0: float
    span: float
    win_lo: float
    win_hi: float
    brackets: Brackets


@dataclass
class Batch:
    """Chunks gathered for one refinement."""

    chunks: list[Chunk] = field(default_factory=list)
    size: int = 0  #: brackets held

    def add(self, chunk: Chunk) -> None:
        self.chunks.append(chunk)
        br = chunk.brackets
        self.size += len(br.crossings) + len(br.peaks) + len(br.culminations)

    def merged(self) -> tuple[list[Any], np.ndarray, np.ndarray, Layout, Brackets]:
        """The batch's models, per-satellite reference instants (jd0, fr0), layout, and the brackets of
        every chunk with batch satellite indices.  Empties the batch: the chunks' own brackets are freed
        while the merged ones are refined."""
        counts = [len(c.models) for c in self.chunks]
        starts = np.concatenate(([0], np.cumsum(counts)[:-1])).astype(np.intp)

        def per_sat(values: list[float]) -> np.ndarray:
            return np.repeat(np.array(values, dtype=np.float64), counts)

        layout = Layout(np.concatenate([c.catalog_numbers for c in self.chunks]),
                        per_sat([c.span for c in self.chunks]), per_sat([c.win_lo for c in self.chunks]),
                        per_sat([c.win_hi for c in self.chunks]), starts)
        models = [m for c in self.chunks for m in c.models]
        kinds = ("crossings", "peaks", "culminations")
        parts: dict[str, list[Intervals]] = {kind: [] for kind in kinds}
        for c, first in zip(self.chunks, starts.tolist()):
            for kind in kinds:
                part = getattr(c.brackets, kind)
                part.sat = part.sat + first
                parts[kind].append(part)
        brackets = Brackets(*(Intervals.concat(parts[kind]) for kind in kinds))
        jd0, fr0 = per_sat([c.jd0 for c in self.chunks]), per_sat([c.fr0 for c in self.chunks])
        del parts
        self.chunks, self.size = [], 0
        return models, jd0, fr0, layout, brackets
