"""Value kinds of the configuration table: each turns a TOML value into the value the server uses.

A converter takes the :class:`~nfwserver.config.table.Setting`, the raw TOML value and the
directory relative file names are resolved against (None when converting the table's own
defaults), and returns the converted value or raises :class:`ValueError` whose message is the
reason alone (``"80 is outside 1..50"``); the loader prefixes ``[section] key:``.  A converter
that checks several entries raises :class:`ManyProblems` with complete problem sentences.
"""

from __future__ import annotations

import ipaddress
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

from nfwserver.channels.channel import Channel
from nfwserver.config.files import check_regular_file
from nfwserver.config.setting import Setting
from nfwserver.radio.defaults import DEFAULT_CHANNELS
from nfwserver.tracking.dde_names import validate_dde_name
from nfwserver.tracking.horizon import HorizonTable
from nfwserver.tracking.observer import Observer, parse_observer

Converter = Callable[[Setting, Any, "Path | None"], Any]


class ManyProblems(ValueError):
    """Several complete problem sentences found in one value (channel entries, DDE names)."""

    def __init__(self, problems: list[str]) -> None:
        self.problems = problems
        super().__init__("; ".join(problems))


def _is_int(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _range(setting: Setting, value: float) -> None:
    lo, hi = setting.lo, setting.hi
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        raise ValueError(f"{value:g} is outside {lo:g}..{hi:g}")


def _bool(setting: Setting, value: Any, base: Path | None) -> bool:
    if not isinstance(value, bool):
        raise ValueError("must be true or false")
    return value


def _int(setting: Setting, value: Any, base: Path | None) -> int:
    if not _is_int(value):
        raise ValueError("must be a whole number")
    _range(setting, value)
    return int(value)


def _number(setting: Setting, value: Any, base: Path | None) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ValueError("must be a finite number")
    _range(setting, value)
    return float(value)


def _choice(setting: Setting, value: Any, base: Path | None) -> Any:
    if isinstance(value, bool) or value not in setting.choices:
        raise ValueError("must be one of " + ", ".join(_show(c) for c in setting.choices))
    return value


def _text(setting: Setting, value: Any, base: Path | None) -> str:
    hi = int(setting.hi or 255)
    if not isinstance(value, str) or not 0 < len(value) <= hi or not value.isprintable():
        raise ValueError(f"must be 1 to {hi} printable characters")
    return value


def _list(value: Any, what: str) -> list[Any]:
    if not isinstance(value, list):
        raise ValueError(f"must be a list of {what}")
    return value


def _texts(setting: Setting, value: Any, base: Path | None) -> tuple[str, ...]:
    return tuple(_text(setting, v, base) for v in _list(value, "strings"))


def _choices(setting: Setting, value: Any, base: Path | None) -> tuple[Any, ...]:
    return tuple(_choice(setting, v, base) for v in _list(value, "names"))


def _catnr(setting: Setting, value: Any, base: Path | None) -> int:
    if not _is_int(value) or not 0 < value < 1_000_000_000:
        raise ValueError(f"{_show(value)} is not a catalog number")
    return int(value)


def _satellite(setting: Setting, value: Any, base: Path | None) -> int | str:
    """A catalog number, or a satellite's name as ``SAT=`` takes it (resolved against the catalog at start)."""
    if isinstance(value, str) and value.strip() and len(value) <= 64 and value.isprintable():
        return value.strip()
    if isinstance(value, str):
        raise ValueError("must be a catalog number or a satellite's name (1 to 64 printable characters)")
    return _catnr(setting, value, base)


def _satellites(setting: Setting, value: Any, base: Path | None) -> tuple[int | str, ...]:
    """Catalog numbers or names, each as ``SAT=`` takes it, in the order given (duplicates and more than
    ``setting.hi`` entries are refused)."""
    listed = _list(value, "catalog numbers or names")
    if setting.hi is not None and len(listed) > setting.hi:
        raise ValueError(f"lists {len(listed)} satellites, more than {setting.hi:g}")
    items = tuple(_satellite(setting, v, base) for v in listed)
    seen: set[int | str] = set()
    for item in items:
        key = item.upper() if isinstance(item, str) else item
        if key in seen:
            raise ValueError(f"{_show(item)} is listed twice")
        seen.add(key)
    return items


def _catnrs(setting: Setting, value: Any, base: Path | None) -> tuple[int, ...]:
    return tuple(_catnr(setting, v, base) for v in _list(value, "catalog numbers"))


def _host(setting: Setting, value: Any, base: Path | None) -> str:
    if not isinstance(value, str) or not value or not value.isprintable() or any(c.isspace() for c in value):
        raise ValueError("must be a host name or address")
    return value


def _networks(setting: Setting, value: Any, base: Path | None) -> tuple[str, ...]:
    networks = []
    for item in _list(value, "addresses or networks"):
        try:
            if not isinstance(item, str):
                raise ValueError
            networks.append(str(ipaddress.ip_network(item.strip(), strict=False)))
        except ValueError:
            raise ValueError(f"{_show(item)} is not an IP address or network (e.g. \"10.0.0.0/8\", \"::1\")") from None
    return tuple(networks)


def _urls(setting: Setting, value: Any, base: Path | None) -> tuple[str, ...]:
    urls = _texts(setting, value, base)
    for url in urls:
        if not url.lower().startswith(("http://", "https://")):
            raise ValueError(f"{url!r} is not an http(s) URL")
    return urls


def _url(setting: Setting, value: Any, base: Path | None) -> str:
    return _urls(setting, [value], base)[0]


def _path(value: Any, base: Path | None) -> str:
    if not isinstance(value, str) or not value or "\0" in value:
        raise ValueError("must be a file name")
    return str(base / value) if base is not None else value


def _file(setting: Setting, value: Any, base: Path | None) -> str:
    path = _path(value, base)
    if base is not None and (problem := check_regular_file(path)):
        raise ValueError(problem)
    return path


def _files(setting: Setting, value: Any, base: Path | None) -> tuple[str, ...]:
    return tuple(_file(setting, v, base) for v in _list(value, "file names"))


def _store(setting: Setting, value: Any, base: Path | None) -> str | None:
    """"default" (the user data directory), "none" (off) or a file name."""
    if value == "default":
        return "default"
    if value == "none":
        return None
    try:
        return _path(value, base)
    except ValueError:
        raise ValueError("must be a file name, \"default\" or \"none\"") from None


def _location(setting: Setting, value: Any, base: Path | None) -> Observer:
    if not isinstance(value, str):
        raise ValueError("must be a string such as \"JO02ae\" or \"52.2,0.12,20\"")
    return parse_observer(value)


def _points(setting: Setting, value: Any, base: Path | None) -> HorizonTable:
    if not isinstance(value, list) or not all(
        isinstance(p, list) and len(p) == 2 and all(isinstance(x, int | float) and not isinstance(x, bool) for x in p)
        for p in value
    ):
        raise ValueError("must be a list of [azimuth, elevation] pairs of numbers")
    return HorizonTable([(float(a), float(e)) for a, e in value])


def _by_catalog_number(key: str, value: Any, form: str, convert: Callable[[str], str]) -> dict[int, str]:
    """A ``[satellites] <key>`` table of catalog number = text, each text checked by ``convert``."""
    if not isinstance(value, dict):
        raise ValueError(f"must be a table of catalog number = {form}")
    result: dict[int, str] = {}
    problems = []
    for number, text in value.items():
        try:
            if not (number.isascii() and number.isdigit()) or not 0 < int(number) < 1_000_000_000:
                raise ValueError(f"{number!r} is not a catalog number")
            if not isinstance(text, str):
                raise ValueError("must be a string")
            result[int(number)] = convert(text)
        except ValueError as exc:
            problems.append(f"[satellites] {key}.{number}: {exc}")
    if problems:
        raise ManyProblems(problems)
    return result


def _names(setting: Setting, value: Any, base: Path | None) -> dict[int, str]:
    return _by_catalog_number("names", value, '"NAME"', validate_dde_name)


def _schedules(setting: Setting, value: Any, base: Path | None) -> dict[int, str]:
    from nfwserver.tracking.mode_schedule import parse_schedule

    def checked(text: str) -> str:
        parse_schedule(text)
        return text.strip()

    return _by_catalog_number("schedules", value, '"SCHEDULE" (e.g. 7530 = "000B128A")', checked)


#: Keys of one ``[[satellites.channels]]`` entry: (key, example value, help).
CHANNEL_KEYS: tuple[tuple[str, Any, str], ...] = (
    ("catalog_number", 25544, "the satellite (required)"),
    ("name", "ISS FM", "shown in the console"),
    ("downlink_hz", 437800000, "satellite transmit frequency, Hz (required)"),
    ("uplink_hz", 145990000, "satellite receive frequency, Hz (leave out for a beacon)"),
    ("downlink_mode", "FM", "Hamlib mode name: FM, USB, LSB, CW, ..."),
    ("uplink_mode", "FM", "Hamlib mode name"),
    ("inverting", False, "true for an inverting linear transponder"),
    ("hold", "satellite", "side kept constant: \"satellite\" (both move), \"uplink\" or \"downlink\""),
    ("downlink_correction_hz", 0, "the satellite's own downlink oscillator error, Hz"),
    ("uplink_correction_hz", 0, "the satellite's own uplink oscillator error, Hz"),
    ("passband_offset_hz", 0, "operating point inside a linear passband, Hz"),
)
_CHANNEL_TYPES = {"name": str, "downlink_mode": str, "uplink_mode": str, "hold": str, "inverting": bool}


def _channel(entry: dict[str, Any]) -> tuple[int, Channel]:
    """One channel entry; ValueError naming the first problem."""
    unknown = sorted(set(entry) - {k for k, _, _ in CHANNEL_KEYS})
    if unknown:
        raise ValueError(f"unknown key {', '.join(unknown)} (valid keys: {', '.join(k for k, _, _ in CHANNEL_KEYS)})")
    fields = dict(entry)
    catnr = fields.pop("catalog_number", None)
    if not _is_int(catnr) or not 0 < catnr < 1_000_000_000:
        raise ValueError("catalog_number: must be a catalog number")
    if "downlink_hz" not in fields:
        raise ValueError("downlink_hz: required")
    for key, value in fields.items():
        wanted = _CHANNEL_TYPES.get(key)
        if wanted is str and not (isinstance(value, str) and value.isprintable()):
            raise ValueError(f"{key}: must be a string")
        if wanted is bool and not isinstance(value, bool):
            raise ValueError(f"{key}: must be true or false")
        if wanted is None and (isinstance(value, bool) or not isinstance(value, int | float)
                               or not math.isfinite(value)):
            raise ValueError(f"{key}: must be a finite number of Hz")
    fields.setdefault("name", str(catnr))
    try:
        return catnr, Channel(**fields)
    except (TypeError, ValueError) as exc:
        raise ValueError(str(exc)) from None


def _channels(setting: Setting, value: Any, base: Path | None) -> dict[int, Channel]:
    """Built-in channels, replaced or extended by the configured entries."""
    if not isinstance(value, list):
        raise ValueError("must be an array of tables ([[satellites.channels]])")
    channels = dict(DEFAULT_CHANNELS)
    problems = []
    for index, entry in enumerate(value, start=1):
        where = f"[[satellites.channels]] #{index}"
        if isinstance(entry, dict) and _is_int(entry.get("catalog_number")):
            where += f" (catalog_number {entry['catalog_number']})"
        try:
            if not isinstance(entry, dict):
                raise ValueError("must be a table")
            number, channel = _channel(entry)
            channels[number] = channel
        except ValueError as exc:
            problems.append(f"{where}: {exc}")
    if problems:
        raise ManyProblems(problems)
    return channels


CONVERTERS: dict[str, Converter] = {
    "bool": _bool, "int": _int, "number": _number, "choice": _choice, "text": _text, "texts": _texts,
    "choices": _choices, "catnr": _catnr, "satellite": _satellite, "catnrs": _catnrs, "satellites": _satellites,
    "host": _host, "networks": _networks,
    "urls": _urls, "url": _url, "file": _file, "files": _files, "store": _store, "location": _location,
    "points": _points, "names": _names, "schedules": _schedules, "channels": _channels, "device": _text,
}


def convert(setting: Setting, value: Any, base: Path | None) -> Any:
    """The server's value for ``value`` of ``setting``; raises :class:`ValueError` with the reason."""
    return CONVERTERS[setting.kind](setting, value, base)


def _show(value: Any) -> str:
    return f'"{value}"' if isinstance(value, str) else str(value)
