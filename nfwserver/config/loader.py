"""Reading and validating the TOML configuration against the table in :mod:`nfwserver.config.table`.

Every problem names the exact key and the reason (``[server] rate_hz: 80 is outside 1..50``), and
a file with any problem is refused whole: the server never starts half-configured.  An unknown
key or section is an error that lists the valid ones (a typo would otherwise be silently
ignored); a section with an unknown key skips its cross-key checks, so a typo is reported alone
and not also as a missing key.  Accepted settings that expose a listener beyond this machine are
returned in :attr:`Config.warnings` for the caller to log at start.
"""

from __future__ import annotations

import difflib
import ipaddress
import sys
from dataclasses import replace
from pathlib import Path
from typing import Any

from nfwserver.config.files import FileRefused, default_config_path, read_regular_file
from nfwserver.config.kinds import ManyProblems, convert
from nfwserver.config.schema import (
    DEFAULT_OBSERVER,
    AutotrackConfig,
    Config,
    DialectsConfig,
    EasyCommConfig,
    ElementsConfig,
    RadioConfig,
    RotorConfig,
    ServerConfig,
    TcpConfig,
    WebConfig,
)
from nfwserver.config.table import SECTION_NAMES, SETTINGS, keys_of, setting
from nfwserver.config.tokens import new_token, weak_token_reason
from nfwserver.tracking.horizon import HorizonTable, parse_horizon
from nfwserver.tracking.observer import Observer

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

#: What :func:`toml_document` raises for text that is not TOML.
TomlError = tomllib.TOMLDecodeError


def toml_document(text: str) -> dict[str, Any]:
    """``text`` as a TOML document; a UTF-8 BOM (Windows editors write one) is skipped.  Raises TomlError."""
    document: dict[str, Any] = tomllib.loads(text.removeprefix("\ufeff"))
    return document


#: Config fields holding a section record, by field name.
_RECORDS = {"elements": ElementsConfig, "server": ServerConfig, "radio": RadioConfig, "rotor": RotorConfig,
            "dialects": DialectsConfig, "tcp": TcpConfig, "easycomm": EasyCommConfig, "web": WebConfig,
            "autotrack": AutotrackConfig}


class ConfigError(ValueError):
    """The configuration cannot be used; ``problems`` lists each one as 'key: reason'."""

    def __init__(self, source: str, problems: list[str]) -> None:
        self.source = source
        self.problems = problems
        super().__init__(f"{source}: " + "; ".join(problems))


def _unknown(where: str, kind: str, name: str, valid: tuple[str, ...]) -> str:
    """``[x] y: unknown key (did you mean z? valid keys: ...)``."""
    close = difflib.get_close_matches(name, valid, n=1)
    hint = f"did you mean {close[0]}? " if close else ""
    return f"{where}: unknown {kind} ({hint}valid {kind}s: {', '.join(valid)})"


def exposure(host: str) -> str | None:
    """Why listening on ``host`` reaches beyond this machine, or None for loopback."""
    if host.lower() == "localhost":
        return None
    try:
        ip = ipaddress.ip_address(host.split("%", 1)[0])
    except ValueError:
        return f"the host name {host!r} may resolve to an address other hosts can reach"
    if ip.is_loopback:
        return None
    if ip.is_unspecified:
        return "it listens on every network interface, so any host that can reach this machine gets in"
    return f"it listens on {host}, reachable from other hosts on that network"


class _Reading:
    """One pass over a parsed TOML document: converted values by (section, key) and the problems."""

    def __init__(self, doc: dict[str, Any], base: Path) -> None:
        self.base = base
        self.problems: list[str] = []
        self.values: dict[tuple[str, str], Any] = {}
        self.dirty: set[str] = set()  #: sections with an unknown key or a wrong shape
        self.present: set[tuple[str, str]] = set()  #: keys written in the file, valid or not
        for name in doc:
            if name not in SECTION_NAMES:
                self.problems.append(_unknown(f"[{name}]", "section", name, SECTION_NAMES))
        for section in SECTION_NAMES:
            table = doc.get(section, {})
            if not isinstance(table, dict):
                self.problems.append(f"[{section}]: must be a table")
                self.dirty.add(section)
                continue
            valid = keys_of(section)
            for key in table:
                if key not in valid:
                    self.problems.append(_unknown(f"[{section}] {key}", "key", key, valid))
                    self.dirty.add(section)
            for key in valid:
                if key in table:
                    self.present.add((section, key))
                    self._convert(section, key, table[key])

    def _convert(self, section: str, key: str, raw: Any) -> None:
        entry = setting(section, key)
        try:
            self.values[(section, key)] = convert(entry, raw, self.base)
        except ManyProblems as exc:
            self.problems.extend(exc.problems)
        except ValueError as exc:
            self.problems.append(f"{entry.name}: {exc}")

    def given(self, section: str, key: str) -> bool:
        return (section, key) in self.values

    def get(self, section: str, key: str) -> Any:
        return self.values.get((section, key))

    def observer(self) -> Observer | None:
        coords = [k for k in ("latitude_deg", "longitude_deg", "altitude_m") if ("observer", k) in self.present]
        if ("observer", "location") in self.present:
            if coords:
                self.problems.append(f"[observer]: give location or {', '.join(coords)}, not both")
            location: Observer | None = self.get("observer", "location")
            return location
        if not coords or "observer" in self.dirty or any(not self.given("observer", k) for k in coords):
            return None
        missing = [k for k in ("latitude_deg", "longitude_deg") if not self.given("observer", k)]
        if missing:
            self.problems.append(f"[observer] {missing[0]}: required with {coords[0]}")
            return None
        return Observer(self.get("observer", "latitude_deg"), self.get("observer", "longitude_deg"),
                        self.get("observer", "altitude_m") or 0.0)

    def horizon(self) -> HorizonTable:
        path = self.get("horizon", "file")
        if ("horizon", "points") in self.present and ("horizon", "file") in self.present:
            self.problems.append("[horizon]: give either points or file, not both")
            return HorizonTable()
        if path is None:
            return self.get("horizon", "points") or HorizonTable()
        try:
            return parse_horizon(read_regular_file(path, errors="replace"), source=path)
        except FileNotFoundError:
            self.problems.append(f"[horizon] file: {path} does not exist")
        except OSError as exc:
            self.problems.append(f"[horizon] file: {path} cannot be read ({exc.strerror or exc})")
        except ValueError as exc:  # FileRefused, or a bad line
            self.problems.append(f"[horizon] file: {exc}")
        return HorizonTable()

    def cross_checks(self) -> None:
        step, knob = self.get("radio", "step_hz"), self.get("radio", "knob_tolerance_hz")
        if "radio" not in self.dirty and step is not None and knob is not None and knob < step:
            self.problems.append(f"[radio] knob_tolerance_hz: {knob:g} must be at least step_hz ({step:g})")
        if ("easycomm" not in self.dirty and self.get("easycomm", "enabled")
                and ("easycomm", "device") not in self.present):
            self.problems.append("[easycomm] device: required when enabled (e.g. \"/dev/ttyUSB0\")")
        token = self.get("web", "token")
        if "web" not in self.dirty and self.get("web", "control") and not token:
            self.problems.append("[web] token: required when control is on (at least 8 characters; for a "
                                 f"fresh one: nfwserver config set web.token {new_token()})")
        elif "web" not in self.dirty and token is not None and (why := weak_token_reason(token)):
            self.problems.append(f"[web] token: {why} (for a fresh one: nfwserver config set web.token "
                                 f"{new_token()})")

    def warnings(self, config: Config) -> tuple[str, ...]:
        found = []
        if config.tcp.enabled and (why := exposure(config.tcp.host)):
            found.append(f"[tcp] host = \"{config.tcp.host}\": {why}; only [tcp] allow addresses are served "
                         f"({', '.join(config.tcp.allow)})")
        if config.web.enabled and (why := exposure(config.web.host)):
            found.append(f"[web] host = \"{config.web.host}\": {why}; only [web] allow addresses are served "
                         f"({', '.join(config.web.allow)})")
        if config.dialects.predict_udp and (why := exposure(config.dialects.predict_host)):
            found.append(f"[dialects] predict_host = \"{config.dialects.predict_host}\": {why}; PREDICT UDP "
                         "answers any sender, with replies several times larger than the requests")
        return tuple(found)


def parse_config(text: str, source: str = "<config>", base_dir: Path | None = None) -> Config:
    """Validate TOML text; raises :class:`ConfigError` listing every problem.

    Relative file names are resolved against ``base_dir`` (default: the current directory), and the
    files they name must exist.
    """
    try:
        doc = toml_document(text)
    except TomlError as exc:
        raise ConfigError(source, [f"not valid TOML ({exc})"]) from None
    reading = _Reading(doc, base_dir or Path("."))
    observer = reading.observer()
    horizon = reading.horizon()
    reading.cross_checks()
    if reading.problems:
        raise ConfigError(source, reading.problems)

    records: dict[str, dict[str, Any]] = {name: {} for name in _RECORDS}
    top: dict[str, Any] = {}
    for entry in SETTINGS:
        if entry.section in ("observer", "horizon") or not reading.given(entry.section, entry.key):
            continue
        record, _, name = entry.where.rpartition(".")
        (records[record] if record else top)[name] = reading.get(entry.section, entry.key)
    config = Config(
        observer=observer or DEFAULT_OBSERVER, observer_configured=observer is not None, horizon=horizon,
        horizon_file=reading.get("horizon", "file"), source=source,
        **{name: _RECORDS[name](**values) for name, values in records.items()}, **top,
    )
    warnings = reading.warnings(config)
    return replace(config, warnings=warnings) if warnings else config


def load_config(path: str | Path | None = None) -> Config:
    """Load ``path``, or the default location if it exists, else the built-in defaults.

    Only a regular file of at most 1 MiB is read (a FIFO or device never blocks the caller).
    Raises :class:`ConfigError` for an explicit path that cannot be read or any invalid content.
    """
    if path is None:
        default = default_config_path()
        if not default.exists():
            return Config()
        path = default
    path = Path(path)
    return replace(parse_config(read_config_text(path), str(path), path.parent), path=str(path))


def has_settings(text: str) -> bool:
    """True unless ``text`` is TOML holding no table and no key (empty, blank or comments only).

    Text that is not TOML at all counts as having settings: :func:`parse_config` then names the problem."""
    try:
        return bool(toml_document(text))
    except TomlError:
        return True


def read_config_text(path: Path) -> str:
    """The text of the configuration file ``path``; raises :class:`ConfigError` naming why it cannot be read."""
    try:
        return read_regular_file(path)
    except FileNotFoundError:
        raise ConfigError(str(path), ["cannot read the file: it does not exist"]) from None
    except FileRefused as exc:
        raise ConfigError(str(path), [f"cannot read the file: {exc}"]) from None
    except UnicodeDecodeError:
        raise ConfigError(str(path), ["cannot read the file: it is not UTF-8 text"]) from None
    except OSError as exc:
        raise ConfigError(str(path), [f"cannot read the file ({exc.strerror or exc})"]) from None


def observer_hint(config: Config) -> str:
    """The start-up note when no observer is configured, naming the file the user should edit."""
    if config.path is not None:
        where = f"Set [observer] location in {config.path}."
    else:
        where = (f"Set [observer] location in {default_config_path()} "
                 "(`nfwserver config init` writes a starting file).")
    return f"no observer configured: using {config.observer} (Greenwich). {where}"
