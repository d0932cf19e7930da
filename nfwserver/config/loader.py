"""Reading and validating the TOML configuration.

Every problem names the exact key and the reason (``[server] rate_hz: 80 is outside 1..50``), and
a file with any problem is refused whole: the server never starts half-configured.  Unknown keys
are errors too (a typo would otherwise be silently ignored).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Any

from nfwserver.config.schema import (
    Config,
    DialectsConfig,
    ElementsConfig,
    RadioConfig,
    RotorConfig,
    ServerConfig,
)
from nfwserver.radio.defaults import DEFAULT_CHANNELS
from nfwserver.radio.transponder import Channel
from nfwserver.rotor.geometry import RotorGeometry
from nfwserver.tracking.dde_names import validate_dde_name
from nfwserver.tracking.horizon import HorizonTable, load_horizon
from nfwserver.tracking.observer import Observer, parse_observer

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

APP_NAME = "nfwserver"


class ConfigError(ValueError):
    """The configuration cannot be used; ``problems`` lists each one as 'key: reason'."""

    def __init__(self, source: str, problems: list[str]) -> None:
        self.source = source
        self.problems = problems
        super().__init__(f"{source}: " + "; ".join(problems))


def default_config_path() -> Path:
    """``config.toml`` in the platform's user configuration directory."""
    from platformdirs import user_config_dir

    return Path(user_config_dir(APP_NAME, appauthor=False)) / "config.toml"


class _Checker:
    def __init__(self, source: str) -> None:
        self.source = source
        self.problems: list[str] = []

    def table(self, doc: dict, name: str, allowed: set[str]) -> dict:
        value = doc.get(name, {})
        if not isinstance(value, dict):
            self.problems.append(f"[{name}]: must be a table")
            return {}
        for key in value:
            if key not in allowed:
                self.problems.append(f"[{name}] {key}: unknown key (allowed: {', '.join(sorted(allowed))})")
        return value

    def number(self, section: str, key: str, value: Any, lo: float, hi: float) -> float | None:
        if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
            self.problems.append(f"[{section}] {key}: must be a number")
            return None
        if not lo <= value <= hi:
            self.problems.append(f"[{section}] {key}: {value} is outside {lo:g}..{hi:g}")
            return None
        return float(value)

    def strings(self, section: str, key: str, value: Any) -> tuple[str, ...] | None:
        if not isinstance(value, list) or not all(isinstance(v, str) and v for v in value):
            self.problems.append(f"[{section}] {key}: must be a list of non-empty strings")
            return None
        return tuple(value)


def parse_config(text: str, source: str = "<config>", base_dir: Path | None = None) -> Config:
    """Validate TOML text; raises :class:`ConfigError` listing every problem."""
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(source, [f"not valid TOML ({exc})"]) from None
    c = _Checker(source)
    for key in doc:
        if key not in {"observer", "horizon", "elements", "server", "satellites", "radio", "rotor", "dialects"}:
            c.problems.append(f"[{key}]: unknown section")
    base = base_dir or Path(".")

    # [observer]
    obs_t = c.table(doc, "observer", {"location", "latitude_deg", "longitude_deg", "altitude_m"})
    observer: Observer | None = None
    if "location" in obs_t:
        if not isinstance(obs_t["location"], str):
            c.problems.append("[observer] location: must be a string such as \"JO02ae\" or \"52.2,0.12,20\"")
        else:
            try:
                observer = parse_observer(obs_t["location"])
            except ValueError as exc:
                c.problems.append(f"[observer] location: {exc}")
    elif obs_t:
        lat = c.number("observer", "latitude_deg", obs_t.get("latitude_deg"), -90, 90)
        lon = c.number("observer", "longitude_deg", obs_t.get("longitude_deg"), -180, 360)
        alt = c.number("observer", "altitude_m", obs_t.get("altitude_m", 0.0), -12000, 100000)
        if None not in (lat, lon, alt):
            observer = Observer(lat, lon, alt)  # type: ignore[arg-type]

    # [horizon]
    hor_t = c.table(doc, "horizon", {"points", "file"})
    horizon = HorizonTable()
    if "points" in hor_t and "file" in hor_t:
        c.problems.append("[horizon]: give either points or file, not both")
    elif "points" in hor_t:
        pts = hor_t["points"]
        try:
            if not isinstance(pts, list) or not all(isinstance(p, list) and len(p) == 2 for p in pts):
                raise ValueError("must be a list of [azimuth, elevation] pairs")
            horizon = HorizonTable([(float(a), float(e)) for a, e in pts])
        except (TypeError, ValueError) as exc:
            c.problems.append(f"[horizon] points: {exc}")
    elif "file" in hor_t:
        try:
            horizon = load_horizon(base / str(hor_t["file"]))
        except (OSError, ValueError) as exc:
            c.problems.append(f"[horizon] file: {exc}")

    # [elements]
    el_t = c.table(doc, "elements", {"files", "urls", "refresh_hours", "use_bundled", "store"})
    files = c.strings("elements", "files", el_t.get("files", [])) or ()
    urls = c.strings("elements", "urls", el_t.get("urls", [])) or ()
    for url in urls:
        if not url.lower().startswith(("http://", "https://")):
            c.problems.append(f"[elements] urls: {url!r} is not an http(s) URL")
    refresh = c.number("elements", "refresh_hours", el_t.get("refresh_hours", 24.0), 0, 24 * 30)
    use_bundled = el_t.get("use_bundled", True)
    if not isinstance(use_bundled, bool):
        c.problems.append("[elements] use_bundled: must be true or false")
    store = el_t.get("store", "default")
    if not isinstance(store, str):
        c.problems.append("[elements] store: must be a file name, \"default\" or \"none\"")
        store = "none"
    if store == "default":
        store_path: str | None = "default"
    elif store == "none":
        store_path = None
    else:
        store_path = str(base / store)
    elements = ElementsConfig(tuple(str(base / f) for f in files), urls, refresh or 0.0, bool(use_bundled),
                              store_path)

    # [server]
    sv_t = c.table(doc, "server", {"rate_hz", "services", "topic", "items", "satellite", "ut1_utc_s", "state_file"})
    state_file = sv_t.get("state_file", "default")
    if not isinstance(state_file, str):
        c.problems.append("[server] state_file: must be a file name, \"default\" or \"none\"")
        state_file = "none"
    state_path = None if state_file == "none" else (state_file if state_file == "default" else str(base / state_file))
    rate = c.number("server", "rate_hz", sv_t.get("rate_hz", 5.0), 1, 50)
    services = c.strings("server", "services", sv_t.get("services", ["NFW32", "NFW_SERVER"]))
    items = c.strings("server", "items", sv_t.get("items", ["NFW_SERVER", "NFW_DATA"]))
    topic = sv_t.get("topic", "NFW_DATA")
    for name in [*(services or ()), *(items or ()), topic if isinstance(topic, str) else ""]:
        if not isinstance(name, str) or not 0 < len(name) <= 255:
            c.problems.append(f"[server] DDE name {name!r}: must have 1 to 255 characters")
    satellite = sv_t.get("satellite", 25544)
    if satellite is not None and (isinstance(satellite, bool) or not isinstance(satellite, int) or satellite <= 0):
        c.problems.append("[server] satellite: must be a catalog number")
    ut1 = c.number("server", "ut1_utc_s", sv_t.get("ut1_utc_s", 0.0), -1, 1)

    # [satellites]
    sat_t = c.table(doc, "satellites", {"names", "favourites", "channels"})
    names: dict[int, str] = {}
    raw_names = sat_t.get("names", {})
    if not isinstance(raw_names, dict):
        c.problems.append("[satellites] names: must be a table of catalog number = \"NAME\"")
    else:
        for key, value in raw_names.items():
            try:
                names[int(key)] = validate_dde_name(str(value))
            except ValueError as exc:
                c.problems.append(f"[satellites] names.{key}: {exc}")
    favourites = sat_t.get("favourites", [])
    if not isinstance(favourites, list) or not all(isinstance(f, int) and not isinstance(f, bool) for f in favourites):
        c.problems.append("[satellites] favourites: must be a list of catalog numbers")
        favourites = []

    # [radio]
    ra_t = c.table(doc, "radio", {"backend", "host", "port", "step_hz", "knob_tolerance_hz", "enabled"})
    backend = ra_t.get("backend", "none")
    if backend not in ("none", "rigctld"):
        c.problems.append("[radio] backend: must be \"none\" or \"rigctld\"")
    host = ra_t.get("host", "127.0.0.1")
    if not isinstance(host, str) or not host:
        c.problems.append("[radio] host: must be a host name or address")
    port = c.number("radio", "port", ra_t.get("port", 4532), 1, 65535)
    step = c.number("radio", "step_hz", ra_t.get("step_hz", 10.0), 1, 10000)
    knob = c.number("radio", "knob_tolerance_hz", ra_t.get("knob_tolerance_hz", 100.0), 1, 1e6)
    if step and knob and knob < step:
        c.problems.append("[radio] knob_tolerance_hz: must be at least step_hz")
    radio_enabled = ra_t.get("enabled", False)
    if not isinstance(radio_enabled, bool):
        c.problems.append("[radio] enabled: must be true or false")
    channels = dict(DEFAULT_CHANNELS)
    raw_channels = sat_t.get("channels", [])
    if not isinstance(raw_channels, list):
        c.problems.append("[satellites] channels: must be an array of tables ([[satellites.channels]])")
        raw_channels = []
    for index, entry in enumerate(raw_channels, start=1):
        where = f"[[satellites.channels]] #{index}"
        if not isinstance(entry, dict):
            c.problems.append(f"{where}: must be a table")
            continue
        fields = dict(entry)
        catnr = fields.pop("catalog_number", None)
        if isinstance(catnr, bool) or not isinstance(catnr, int) or catnr <= 0:
            c.problems.append(f"{where} catalog_number: must be a catalog number")
            continue
        try:
            channels[catnr] = Channel(name=str(fields.pop("name", f"{catnr}")), **fields)
        except TypeError as exc:
            c.problems.append(f"{where}: {exc}")
        except ValueError as exc:
            c.problems.append(f"{where}: {exc}")

    # [rotor]
    ro_t = c.table(doc, "rotor", {"backend", "host", "port", "geometry", "threshold_deg", "speed_deg_s", "max_lead_s",
                                  "after_los", "flip", "park_azimuth_deg", "park_elevation_deg",
                                  "park_delay_minutes"})
    ro_backend = ro_t.get("backend", "none")
    if ro_backend not in ("none", "sim", "rotctld"):
        c.problems.append("[rotor] backend: must be \"none\", \"sim\" or \"rotctld\"")
    ro_host = ro_t.get("host", "127.0.0.1")
    if not isinstance(ro_host, str) or not ro_host:
        c.problems.append("[rotor] host: must be a host name or address")
    ro_geometry = ro_t.get("geometry", "north-stop")
    try:
        RotorGeometry.preset(str(ro_geometry))
    except ValueError:
        c.problems.append("[rotor] geometry: must be north-stop, south-stop or overlap-450, optionally with +flip")
    ro_port = c.number("rotor", "port", ro_t.get("port", 4533), 1, 65535)
    ro_threshold = c.number("rotor", "threshold_deg", ro_t.get("threshold_deg", 2.0), 0, 45)
    ro_speed = c.number("rotor", "speed_deg_s", ro_t.get("speed_deg_s", 6.0), 0.1, 90)
    ro_lead = c.number("rotor", "max_lead_s", ro_t.get("max_lead_s", 10.0), 0, 120)
    after_los = ro_t.get("after_los", "park")
    if after_los not in ("park", "next-aos", "stay"):
        c.problems.append("[rotor] after_los: must be \"park\", \"next-aos\" or \"stay\"")
    flip_mode = ro_t.get("flip", "auto")
    if flip_mode not in ("auto", "off"):
        c.problems.append("[rotor] flip: must be \"auto\" or \"off\"")
    park_az = c.number("rotor", "park_azimuth_deg", ro_t.get("park_azimuth_deg", 0), 0, 359)
    park_el = c.number("rotor", "park_elevation_deg", ro_t.get("park_elevation_deg", 0), 0, 90)
    park_delay = c.number("rotor", "park_delay_minutes", ro_t.get("park_delay_minutes", 0), 0, 60)

    # [dialects]
    di_t = c.table(doc, "dialects", {"dde", "predict_udp", "predict_host", "predict_port", "callsign"})
    dde = c.strings("dialects", "dde", di_t.get("dde", [])) or ()
    for name in dde:
        if name not in ("orbitron", "wxtrack", "satpc32"):
            c.problems.append(f"[dialects] dde: {name!r} is not one of orbitron, wxtrack, satpc32")
    predict_udp = di_t.get("predict_udp", False)
    if not isinstance(predict_udp, bool):
        c.problems.append("[dialects] predict_udp: must be true or false")
    predict_host = di_t.get("predict_host", "127.0.0.1")
    if not isinstance(predict_host, str) or not predict_host:
        c.problems.append("[dialects] predict_host: must be a host address")
    predict_port = c.number("dialects", "predict_port", di_t.get("predict_port", 1210), 0, 65535)
    callsign = di_t.get("callsign", "NFWSERVER")
    if not isinstance(callsign, str) or not callsign.isprintable() or not 0 < len(callsign) <= 12:
        c.problems.append("[dialects] callsign: must be 1 to 12 printable characters")

    if c.problems:
        raise ConfigError(source, c.problems)
    return Config(
        observer=observer or Config().observer, observer_configured=observer is not None, horizon=horizon,
        elements=elements,
        server=ServerConfig(rate or 5.0, services or (), str(topic), items or (), satellite, ut1 or 0.0),
        dde_names=names, favourites=tuple(favourites), source=source,
        radio=RadioConfig(str(backend), str(host), int(port or 4532), step or 10.0, knob or 100.0, bool(radio_enabled)),
        channels=channels,
        rotor=RotorConfig(str(ro_backend), str(ro_host), int(ro_port or 4533), str(ro_geometry),
                          ro_threshold if ro_threshold is not None else 2.0, ro_speed or 6.0,
                          ro_lead if ro_lead is not None else 10.0, str(after_los), str(flip_mode),
                          int(park_az or 0), int(park_el or 0), int(park_delay or 0)),
        state_file=state_path,
        dialects=DialectsConfig(tuple(dde), bool(predict_udp), str(predict_host),
                                int(predict_port if predict_port is not None else 1210), str(callsign)),
    )


def load_config(path: str | Path | None = None) -> Config:
    """Load ``path``, or the default location if it exists, else the built-in defaults.

    Raises :class:`ConfigError` for an explicit path that cannot be read or any invalid content.
    """
    if path is None:
        default = default_config_path()
        if not default.exists():
            return Config()
        path = default
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(str(path), [f"cannot read the file ({exc})"]) from None
    return parse_config(text, str(path), path.parent)


TEMPLATE = """\
# nfwserver configuration.  Every key is optional; the values shown are the defaults.
# Run `nfwserver config show` to see what the server makes of this file.

[observer]
# Your station: a Maidenhead locator ("JO02ae") or "LAT,LON[,ALT_M]" ("52.2,0.12,20", "33.87S,151.21E").
# Without it the server uses Greenwich and says so at start.
# location = "JO02ae"

[horizon]
# Minimum elevation by azimuth (degrees), interpolated; decides AH:Y/N.  Empty = flat 0 degrees.
# points = [[0, 5], [90, 12], [180, 3], [270, 8]]
# file = "horizon.txt"          # or a file with one "azimuth elevation" pair per line

[elements]
# files = ["my-keps.txt"]       # TLE, AMSAT verbose or OMM JSON/CSV; relative to this file
# urls = ["https://example.org/amateur.txt"]
refresh_hours = 24              # 0 = never refresh while running
use_bundled = true              # include the bundled amateur and weather satellites
store = "default"               # catalog kept by `nfwserver elements update`: "default", a file, or "none"

[server]
rate_hz = 5                     # publish rate, 1..50 Hz
services = ["NFW32", "NFW_SERVER"]
topic = "NFW_DATA"
items = ["NFW_SERVER", "NFW_DATA"]
satellite = 25544               # AutoTracking satellite at start (catalog number)
ut1_utc_s = 0.0                 # UT1-UTC from IERS Bulletin A (seconds)
state_file = "default"          # remembers the AutoTracking satellite across restarts; "none" to disable

[satellites]
# names = { 25544 = "ISS", 27607 = "SO-50" }   # DDE names (12 characters, no spaces)
# favourites = [25544, 27607, 43017]

# Radio channels (Hz) for Doppler tuning; these add to / replace the built-in ones (ISS, SO-50, AO-91,
# RS-44, AO-7).  hold = "satellite" (both sides move), "uplink" or "downlink" (that side stays put).
# [[satellites.channels]]
# catalog_number = 25544
# name = "ISS FM"
# downlink_hz = 437800000
# uplink_hz = 145990000
# downlink_mode = "FM"
# uplink_mode = "FM"
# inverting = false
# hold = "satellite"
# downlink_correction_hz = 0

[radio]
backend = "none"                # "rigctld" to tune a radio through Hamlib's rigctld
host = "127.0.0.1"
port = 4532
step_hz = 10                    # send a new frequency only after it moved this much
knob_tolerance_hz = 100         # a bigger difference on read-back means the operator retuned
enabled = false                 # Doppler tuning on at start (Ctrl+D in the console toggles it)

[rotor]
backend = "none"                # "rotctld" (Hamlib) or "sim" (a simulated rotor, for trying things out)
host = "127.0.0.1"
port = 4533
geometry = "north-stop"         # north-stop (0..360), south-stop (-180..180), overlap-450; add "+flip"
                                # when the elevation rotor reaches 180 (FlipAnts-style inverted passes)
threshold_deg = 2               # move only when the target moved this much (relays wear out)
speed_deg_s = 6                 # rotor speed, used to aim ahead by the travel time
max_lead_s = 10
after_los = "park"              # "park", "next-aos" (pre-position for the next pass) or "stay"
flip = "auto"                   # "auto": decided at AOS for the whole pass; "off"
park_azimuth_deg = 0
park_elevation_deg = 0
park_delay_minutes = 0          # 0 = park at once after LOS

[dialects]
dde = []                        # also serve other trackers' DDE interfaces: "orbitron", "wxtrack", "satpc32"
predict_udp = false             # PREDICT's UDP protocol, for Linux programs written for PREDICT
predict_host = "127.0.0.1"
predict_port = 1210
callsign = "NFWSERVER"          # reported by PREDICT's GET_QTH
"""
