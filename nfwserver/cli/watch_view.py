"""What ``nfwserver watch`` shows: one update of a running station, as a status block, a plain line or JSON.

An update is one ``STATUS`` line (``key=value`` pairs, see :mod:`nfwserver.tcp.protocol`) and the ``SUMMARY``
reply (the Nova string the station publishes, empty while the feed is off), or why the station could not be
asked.  Angles in degrees, range rate in km/s (positive receding), element ages in days; times are this
machine's clock in UTC.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from datetime import datetime

from nfwserver.core.status import describe
from nfwserver.tcp.status_line import parse_status as parse_status  # the one STATUS codec

#: STATUS fields turned into JSON numbers and booleans (the rest stay strings).
_FLOATS = ("az", "el", "rr", "elements_age_d", "rotor_az", "rotor_el")
_INTS = ("satellite", "interface", "radio_rx", "radio_tx")
_SWITCHES = ("tune", "track", "radio_tuning", "auto")


@dataclass(frozen=True)
class WatchUpdate:
    """One look at the station at ``where`` (``host port N``), taken at ``time`` (aware UTC)."""

    time: datetime
    where: str
    connected: bool
    fields: Mapping[str, str] = field(default_factory=dict)  #: the STATUS pairs, as sent
    nova: str = ""  #: the SUMMARY reply: the Nova string being published ("" while the feed is off)
    problem: str = ""  #: why the station could not be asked (when not connected)
    retry_s: float | None = None  #: seconds until the next attempt (when not connected)
    ever_connected: bool = True  #: False until the first answer: "not reachable" rather than "lost"

    def to_json(self) -> dict[str, object]:
        """A JSON-ready object: ``time``, ``station``, ``connected``, then either ``nova``, ``status`` (the raw
        pairs) and the typed values (``az``/``el``/``rr`` numbers, ``ah``/``tune``/``track`` booleans, ``faults``
        a list), or ``error`` and ``retry_s``."""
        stamp = self.time.strftime("%Y-%m-%dT%H:%M:%S.") + f"{self.time.microsecond // 1000:03d}Z"
        out: dict[str, object] = {"time": stamp, "station": self.where, "connected": self.connected}
        if not self.connected:
            out.update(error=self.problem, retry_s=self.retry_s, ever_connected=self.ever_connected)
            return out
        out["nova"] = self.nova
        out["status"] = dict(self.fields)
        for key, value in self.fields.items():
            if value == "-":
                out[key] = None
            elif key in _FLOATS:
                out[key] = _number(value, float)
            elif key in _INTS:
                out[key] = _number(value, int)
            elif key in _SWITCHES:
                out[key] = value == "on"
            elif key == "ah":
                out[key] = value == "Y"
            elif key == "elements_stale":
                out[key] = value == "yes"
            elif key == "faults":
                out[key] = [] if value == "none" else value.split(",")
            elif key == "status":
                out["status_word"] = value
                out["status_bits"] = _bits(value)
            elif key not in out:
                out[key] = value
        return out


def _number(text: str, kind: type[int] | type[float]) -> int | float | str:
    try:
        return kind(text)
    except ValueError:
        return text


def _bits(word: str) -> list[str]:
    try:
        return describe(int(word, 16))
    except ValueError:
        return []


def _time(when: datetime) -> str:
    return when.strftime("%H:%M:%S UTC")


def down_text(update: WatchUpdate) -> str:
    """One sentence for a station that did not answer."""
    state = "lost" if update.ever_connected else "not reachable yet"
    retry = f"; retrying in {update.retry_s:g} s" if update.retry_s is not None else ""
    return f"station {state}: {update.problem}{retry}"


def block_lines(update: WatchUpdate) -> list[str]:
    """The status block: one line per topic, at most 72 characters of values per line."""
    head = f"{update.where}  {_time(update.time)}"
    if not update.connected:
        return [head, down_text(update), "(Ctrl+C to stop)"]
    f = update.fields
    by = f.get("satellite_from", "-")
    lines = [head + "  connected",
             f"Satellite  {f.get('name', '-')} ({f.get('satellite', '-')}), chosen by {by}",
             f"Nova       {update.nova or '(nothing published: TUNE OFF or nothing to compute)'}",
             f"Position   AZ {f.get('az', '-')}  EL {f.get('el', '-')}  RR {f.get('rr', '-')} km/s  "
             f"AH {f.get('ah', '-')}",
             f"Switches   TUNE {f.get('tune', '-').upper()}  TRACK {f.get('track', '-').upper()}  "
             f"radio tuning {f.get('radio_tuning', '-')}"]
    bits = _bits(f.get("status", ""))
    lines.append(f"Status     {f.get('status', '-')}" + (f": {', '.join(bits)}" if bits else ""))
    faults = [f"{key[:-6]}: {value.replace('_', ' ')}" for key, value in f.items() if key.endswith("_fault")]
    lines.append(f"Faults     {'; '.join(faults) if faults else f.get('faults', 'none')}")
    if "rotor" in f:
        rotor = f"Rotor      {f['rotor']}"
        if "rotor_az" in f:
            rotor += f"  at {f['rotor_az']}/{f.get('rotor_el', '-')}"
        if "rotor_target" in f:
            rotor += f"  target {f['rotor_target']}"
        lines.append(rotor)
    if "radio" in f:
        radio = f"Radio      {f['radio']}"
        if "radio_rx" in f:
            radio += f"  rx {f['radio_rx']} Hz"
        if "radio_tx" in f:
            radio += f"  tx {f['radio_tx']} Hz"
        lines.append(radio)
    if "easycomm" in f:
        lines.append(f"EasyComm   {f['easycomm']}")
    if "auto" in f:
        why = f"  ({f['auto_off']})" if f.get("auto_off", "-") != "-" else ""
        lines.append(f"Autotrack  {f['auto'].upper()}{why}  next pass {f.get('auto_next', '-')}")
    if "elements_age_d" in f:
        stale = "  STALE: `nfwserver elements update`" if f.get("elements_stale") == "yes" else ""
        lines.append(f"Elements   {f['elements_age_d']} days old{stale}")
    return lines


def plain_line(update: WatchUpdate) -> str:
    """One line per update, for a log or a pipe."""
    if not update.connected:
        return f"{_time(update.time)}  {down_text(update)}"
    f = update.fields
    text = update.nova or f"{f.get('name', '-')} (feed off)"
    keys = ("tune", "track", "auto", "status", "faults", "rotor", "radio", "easycomm", "elements_age_d")
    return f"{_time(update.time)}  {text}  " + " ".join(f"{k}={f[k]}" for k in keys if k in f)
