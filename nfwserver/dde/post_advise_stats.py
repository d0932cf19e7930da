"""What real DDEML costs the station: wall time of ``DdePostAdvise`` calls, for the log at stop.

``DdePostAdvise(topic, item)`` runs our ``XTYP_ADVREQ`` callback once per advise link on the item
and posts the data to each client before it returns, so its wall time is the DDE share of a tick.
The Windows transport calls it once per tick and item (on its DDE thread) and records each call
here with the number of advise links on its item at that moment.  At stop the transport logs
:meth:`PostAdviseStats.summary`, one line: every call, the calls at the link count (above 0) seen
most often (a station's steady state), and the calls on items nobody advises on (the station posts
every served item each tick); ``python -m bench wine-dde`` reads it.
:func:`parse_summary` reads that line back.  Times in seconds here, milliseconds in the line.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field


@dataclass
class CallTally:
    """Count, total and largest wall time (s) of a set of calls."""

    count: int = 0
    total_s: float = 0.0
    max_s: float = 0.0

    def add(self, seconds: float) -> None:
        self.count += 1
        self.total_s += seconds
        self.max_s = max(self.max_s, seconds)

    @property
    def mean_s(self) -> float:
        return self.total_s / self.count if self.count else 0.0


@dataclass
class PostAdviseStats:
    """Wall time (s) of ``DdePostAdvise`` calls, in all and by the number of advise links served."""

    all: CallTally = field(default_factory=CallTally)
    by_links: dict[int, CallTally] = field(default_factory=dict)

    def add(self, seconds: float, links: int) -> None:
        """Record one call that took ``seconds`` with ``links`` advise links on its item."""
        self.all.add(seconds)
        self.by_links.setdefault(links, CallTally()).add(seconds)

    @property
    def count(self) -> int:
        return self.all.count

    @property
    def mean_s(self) -> float:
        return self.all.mean_s

    @property
    def max_s(self) -> float:
        return self.all.max_s

    def steady_links(self) -> int | None:
        """The link count above 0 with the most calls (the larger count on a tie); None if no call
        served a link."""
        served = [links for links in self.by_links if links > 0]
        if not served:
            return None
        return max(served, key=lambda links: (self.by_links[links].count, links))

    def summary(self) -> str:
        """One log line, e.g. ``DdePostAdvise: 1200 calls, mean 1.000 ms, max 9.000 ms; at 20 advise
        links (580 calls): mean 1.900 ms, max 9.000 ms; at no link (600 calls): mean 0.100 ms, max
        0.400 ms``.  The station posts every item each tick, also items nobody advises on."""
        line = f"DdePostAdvise: {self.all.count} calls, {_figures(self.all)}"
        links = self.steady_links()
        if links is not None:
            tally = self.by_links[links]
            line += f"; at {links} advise links ({tally.count} calls): {_figures(tally)}"
        idle = self.by_links.get(0)
        if idle is not None:
            line += f"; at no link ({idle.count} calls): {_figures(idle)}"
        return line


def _figures(tally: CallTally) -> str:
    return f"mean {tally.mean_s * 1e3:.3f} ms, max {tally.max_s * 1e3:.3f} ms"


_FIGURES = r"mean (?P<{0}mean_ms>[\d.]+) ms, max (?P<{0}max_ms>[\d.]+) ms"
_SUMMARY = re.compile(
    r"DdePostAdvise: (?P<count>\d+) calls, " + _FIGURES.format("")
    + r"(?:; at (?P<links>\d+) advise links \((?P<steady_count>\d+) calls\): " + _FIGURES.format("steady_") + ")?"
    + r"(?:; at no link \((?P<idle_count>\d+) calls\): " + _FIGURES.format("idle_") + ")?")


def parse_summary(text: str) -> dict[str, float] | None:
    """The figures of the last :meth:`PostAdviseStats.summary` line in ``text`` (a log), or None.

    Keys: count, mean_ms, max_ms; when the line has them, links, steady_count, steady_mean_ms,
    steady_max_ms (the calls at the usual link count) and idle_count, idle_mean_ms, idle_max_ms
    (the calls on items without a link).
    """
    matches = list(_SUMMARY.finditer(text))
    if not matches:
        return None
    return {key: float(value) for key, value in matches[-1].groupdict().items() if value is not None}
