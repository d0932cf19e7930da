"""Text generated from the configuration table: the ``config init`` template and ``config show``.

The template lists every key of :data:`~nfwserver.config.table.SETTINGS` with its help text as a
comment: keys with a default are written with it (so the file means exactly the defaults), keys
that are not set by default are written commented out with an example.  ``config show`` prints
every key with its effective value, read from the :class:`~nfwserver.config.schema.Config`.
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Mapping
from operator import attrgetter
from typing import Any

from nfwserver.channels.channel import Channel
from nfwserver.config.kinds import CHANNEL_KEYS
from nfwserver.config.schema import Config
from nfwserver.config.setting import Setting
from nfwserver.config.table import SECTIONS, SETTINGS
from nfwserver.tracking.horizon import HorizonTable

_WIDTH = 100


def toml_value(value: Any) -> str:
    """``value`` written as a TOML value (bools, numbers, strings, lists, tables)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        if math.isfinite(value):
            return f"{value:g}" if value == int(value) and abs(value) < 1e15 else repr(value)
        return "nan" if value != value else ("inf" if value > 0 else "-inf")
    if isinstance(value, int):
        return str(value)
    if isinstance(value, str):
        return _toml_string(value)
    if isinstance(value, list | tuple):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{_toml_key(str(k))} = {toml_value(v)}" for k, v in value.items()) + " }" \
            if value else "{}"
    raise TypeError(f"no TOML form for {value!r}")


def _toml_string(text: str) -> str:
    """A TOML basic string: quotes, backslashes and control characters escaped, the rest literal."""
    out = []
    for char in text:
        if char in '"\\':
            out.append("\\" + char)
        elif ord(char) < 0x20 or ord(char) == 0x7F:
            out.append(f"\\u{ord(char):04x}")
        else:
            out.append(char)
    return '"' + "".join(out) + '"'


def _toml_key(key: str) -> str:
    return key if key and all(c.isalnum() or c in "-_" for c in key) and key.isascii() else _toml_string(key)


def _comment(text: str, indent: str = "") -> list[str]:
    return textwrap.wrap(text, _WIDTH, initial_indent=f"{indent}# ", subsequent_indent=f"{indent}# ")


def _template_lines(entry: Setting) -> list[str]:
    lines = _comment(f"{entry.key}: {entry.help}{_limits(entry)}")
    if entry.kind == "channels":
        lines.append("# [[satellites.channels]]")
        for key, example, help_text in CHANNEL_KEYS:
            lines.append(f"# {f'{key} = {toml_value(example)}':<40} # {help_text}")
        return lines
    if entry.initial is not None:
        lines += _comment(f"(a starting choice; without this line: {entry.key} = {toml_value(entry.default)})")
        lines.append(f"{entry.key} = {toml_value(entry.initial)}")
    elif entry.example is not None or entry.default is None:
        lines.append(f"# {entry.key} = {toml_value(entry.example)}")
    else:
        lines.append(f"{entry.key} = {toml_value(entry.default)}")
    return lines


def _limits(entry: Setting) -> str:
    if entry.kind in ("number", "int") and entry.lo is not None:
        return f" ({_number(entry.lo)}..{_number(entry.hi)})"
    if entry.kind in ("choice", "choices") and 3 < len(entry.choices) <= 12:
        return " (" + ", ".join(str(c) for c in entry.choices) + ")"
    return ""


def _number(value: float | None) -> str:
    return f"{value:g}" if value is None or abs(value) < 1e6 else f"{value:.0f}"


def template() -> str:
    """The commented starting file written by ``nfwserver config init``."""
    out = ["# nfwserver configuration.  Every key is optional: the values written below are the defaults",
           "# (except the starting choices, marked), and commented-out lines show keys that are not set by default.",
           "# Run `nfwserver config show` to see what the server makes of this file."]
    for section in SECTIONS:
        out += ["", f"[{section.name}]", *_comment(section.help)]
        for entry in SETTINGS:
            if entry.section == section.name:
                out += _template_lines(entry)
    return "\n".join(out) + "\n"


def _channel_line(number: int, channel: Channel) -> str:
    up = f", up {channel.uplink_hz:.0f} Hz {channel.uplink_mode}" if channel.uplink_hz is not None else ""
    return (f"#   {number}: {channel.name}: down {channel.downlink_hz:.0f} Hz {channel.downlink_mode}{up}"
            f"{', inverting' if channel.inverting else ''}, hold {channel.hold}")


def _effective(config: Config, entry: Setting) -> Any:
    if entry.key == "location":
        obs = config.observer
        return f"{obs.latitude_deg:.5f},{obs.longitude_deg:.5f},{obs.altitude_m:g}" \
            if config.observer_configured else None
    value = attrgetter(entry.where)(config)
    if isinstance(value, HorizonTable):
        return value.points
    if isinstance(value, tuple) and value and isinstance(value[0], tuple):
        return [list(v) for v in value]
    if entry.key == "names":
        return {str(k): v for k, v in value.items()}
    return value


def show(config: Config, notes: dict[str, str] | None = None, written: Mapping[str, Any] | None = None) -> str:
    """Every key with its effective value; ``notes`` adds a comment to ``"section.key"`` lines.  A key
    given in ``written`` (the file's TOML document) as a number or a location is shown as the user wrote it
    (``location = "JO01ab"``, not the latitude it stands for); values derived from others are rounded for
    reading; paths are shown resolved."""
    notes = dict(notes or {})
    written = written or {}
    if not config.observer_configured:
        notes.setdefault("observer.location", f"not set: using {config.observer} (Greenwich)")
    if not config.horizon.points:
        notes.setdefault("horizon.points", "flat 0-degree horizon")
    out = [f"# configuration: {config.path or config.source}"]
    out += [f"# warning: {w}" for w in config.warnings]
    for section in SECTIONS:
        out += ["", f"[{section.name}]"]
        for entry in SETTINGS:
            if entry.section != section.name:
                continue
            value = _effective(config, entry)
            note = notes.get(f"{entry.section}.{entry.key}")
            if entry.kind == "channels":
                out.append(f"channels = {len(value)} channels" + (f"  # {note}" if note else ""))
                out += [_channel_line(n, c) for n, c in sorted(value.items())]
                continue
            given = written.get(entry.section, {})
            raw = given.get(entry.key) if isinstance(given, Mapping) else None
            if isinstance(raw, int | float) or entry.key == "location" and raw is not None:
                text = toml_value(raw)  # as written (paths and names stay resolved: more useful)
            elif value is None:
                text = "(not set)"
            elif isinstance(value, float) and not isinstance(value, bool):
                text = f"{value:.10g}"  # derived or default: rounded for reading
            else:
                text = toml_value(value)
            out.append(f"{entry.key} = {text}" + (f"  # {note}" if note else ""))
    return "\n".join(out) + "\n"

