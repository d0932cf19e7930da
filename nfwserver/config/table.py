"""The configuration as one table: every section and key, its kind, range or choices, default and help.

Validation (:mod:`nfwserver.config.loader`), ``nfwserver config show`` and the ``config init``
template (:mod:`nfwserver.config.render`) are generated from :data:`SETTINGS`; the record types in
:mod:`nfwserver.config.schema` take their defaults from it through :func:`default`.  Nothing else
holds a copy of a default or a help text.

``default`` is the TOML value a key has when the file leaves it out; ``None`` means "not set"
(the template then shows ``example`` commented out).  ``where`` is the dotted path of the
effective value on :class:`~nfwserver.config.schema.Config` (what ``config show`` prints).
Units are in the key names (``_hz``, ``_deg``, ``_s``, ``_m``).
"""

from __future__ import annotations

from typing import Any

from nfwserver.config.element_presets import DEFAULT_PRESET, PRESETS
from nfwserver.config.kinds import convert
from nfwserver.config.setting import Section, Setting

#: Hamlib's standard serial rates (baud).
STANDARD_BAUD_RATES = (1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200)
ROTOR_GEOMETRIES = tuple(f"{base}{flip}" for base in ("north-stop", "south-stop", "overlap-450")
                         for flip in ("", "+flip"))


SECTIONS: tuple[Section, ...] = (
    Section("observer", "Your station: give location, or latitude_deg and longitude_deg.  Without it the server "
                        "uses Greenwich and says so at start."),
    Section("horizon", "Minimum elevation by azimuth (degrees), interpolated; decides AH:Y/N.  Give points or file "
                       "(not both); neither = a flat 0-degree horizon."),
    Section("elements", "Where orbital elements come from.  Relative file names are relative to this file."),
    Section("server", "The Nova for Windows DDE server."),
    Section("satellites", "Names and channels of particular satellites."),
    Section("radio", "Doppler tuning of a radio through Hamlib's rigctld."),
    Section("rotor", "The antenna rotor (KCT driver model)."),
    Section("dialects", "Other trackers' interfaces served beside Nova's."),
    Section("tcp", "Nova's TCP server: a greeting, SUMMARY, the Nova pokes as commands, STATUS and WATCH."),
    Section("easycomm", "EasyComm I output on a serial port, for Arduino and K3NG-style rotor controllers."),
    Section("autotrack", "Unattended operation: the station selects by itself the satellite of the next pass worth "
                         "working, by priority (docs/AUTOTRACK.md gives the rule; `nfwserver schedule` shows it)."),
    Section("web", "The web dashboard: the station's state live in a browser (phone or PC), nothing from the "
                   "internet; controls only when control is on, each request carrying the token."),
)

_S = Setting
SETTINGS: tuple[Setting, ...] = (
    # [observer]
    _S("observer", "location", "location", None, "a Maidenhead locator (\"JO02ae\") or \"LAT,LON[,ALT_M]\" "
       "(\"52.2,0.12,20\", \"33.87S,151.21E\")", "observer", example="JO02ae"),
    _S("observer", "latitude_deg", "number", None, "geodetic latitude, degrees north (instead of location)",
       "observer.latitude_deg", -90, 90, example=52.2),
    _S("observer", "longitude_deg", "number", None, "longitude, degrees east (instead of location)",
       "observer.longitude_deg", -180, 360, example=0.12),
    _S("observer", "altitude_m", "number", None, "height above the WGS84 ellipsoid, metres (default 0)",
       "observer.altitude_m", -12000, 100000, example=20),
    # [horizon]
    _S("horizon", "points", "points", None, "[azimuth, elevation] pairs, degrees", "horizon.points",
       example=[[0, 5], [90, 12], [180, 3], [270, 8]]),
    _S("horizon", "file", "file", None, "a file with one \"azimuth elevation\" pair per line (at most 1 MiB)",
       "horizon_file", example="horizon.txt"),
    # [elements]
    _S("elements", "files", "files", [], "TLE, AMSAT verbose or OMM JSON/CSV files; each must exist",
       "elements.files", example=["my-keps.txt"]),
    _S("elements", "urls", "urls", [], "element URLs (http or https)", "elements.urls",
       example=["https://example.org/amateur.txt"]),
    _S("elements", "sources", "choices", [], "named sources (`nfwserver elements sources` lists them): CelesTrak "
       "groups as TLE (\"amateur\", \"weather\", \"active\" ...), OMM JSON (\"amateur-json\") or OMM CSV "
       "(\"amateur-csv\"), and \"amsat\" (AMSAT's bare TLE file)", "elements.sources", choices=tuple(PRESETS),
       initial=[DEFAULT_PRESET]),
    _S("elements", "preset_mirror", "url", None, "fetch the named sources from this base URL instead of their own "
       "sites (a local mirror)", "elements.preset_mirror", example="http://mirror.example/elements"),
    _S("elements", "refresh_hours", "number", 24, "read files, URLs and named sources again this often while "
       "running; 0 = never",
       "elements.refresh_hours", 0, 24 * 30),
    _S("elements", "use_bundled", "bool", True, "include the bundled amateur and weather satellites",
       "elements.use_bundled"),
    _S("elements", "store", "store", "default", "catalog kept by `nfwserver elements update`: \"default\" (the user "
       "data directory), a file, or \"none\"", "elements.store"),
    _S("elements", "max_source_mib", "number", 64, "largest element file or download read, MiB; a larger source "
       "is refused whole", "elements.max_source_mib", 0.001, 1024),
    _S("elements", "max_source_sets", "int", 100_000, "most element sets one file or URL may hold; a source with "
       "more is refused whole", "elements.max_source_sets", 1, 1_000_000),
    _S("elements", "stale_days", "number", 14, "element sets older than this are flagged in `passes`, `status` and "
       "the console", "elements.stale_days", 0.1, 3650),
    # [server]
    _S("server", "rate_hz", "number", 5, "publish rate, Hz", "server.rate_hz", 1, 50),
    _S("server", "services", "texts", ["NFW32", "NFW_SERVER"], "DDE service names served", "server.services", hi=255),
    _S("server", "topic", "text", "NFW_DATA", "DDE topic", "server.topic", hi=255),
    _S("server", "items", "texts", ["NFW_SERVER", "NFW_DATA"], "DDE items served", "server.items", hi=255),
    _S("server", "satellite", "satellite", 25544, "AutoTracking satellite at start (catalog number, or a name "
       "that matches one satellite only, as SAT= takes it)",
       "server.satellite"),
    _S("server", "ut1_utc_s", "number", 0.0, "UT1-UTC from IERS Bulletin A, seconds", "server.ut1_utc_s", -1, 1),
    _S("server", "state_file", "store", "default", "remembers the AutoTracking satellite across restarts: "
       "\"default\", a file, or \"none\"", "state_file"),
    _S("server", "tune", "bool", False, "publish from the start, as if a client had poked TUNE ON",
       "server.tune"),
    _S("server", "track", "bool", False, "drive the rotor from the start, as if TRACK ON had been poked",
       "server.track"),
    # [satellites]
    _S("satellites", "names", "names", {}, "DDE names by catalog number (12 characters, no spaces)",
       "dde_names", example={"25544": "ISS", "27607": "SO-50"}),
    _S("satellites", "favourites", "catnrs", [], "satellites whose passes the console lists", "favourites",
       example=[25544, 27607, 43017]),
    _S("satellites", "schedules", "schedules", {}, "InstantTrack mode schedules by catalog number: three-digit "
       "phases (0-255) each followed by the mode then in force", "schedules", example={"7530": "000B128A"}),
    _S("satellites", "channels", "channels", [], "radio channels for Doppler tuning, as [[satellites.channels]] "
       "tables; they add to or replace the built-in ones (ISS, SO-50, AO-91, RS-44, AO-7)", "channels"),
    # [radio]
    _S("radio", "backend", "choice", "none", "\"rigctld\" to tune a radio through Hamlib's rigctld",
       "radio.backend", choices=("none", "rigctld")),
    _S("radio", "host", "host", "127.0.0.1", "rigctld's address", "radio.host"),
    _S("radio", "port", "int", 4532, "rigctld's TCP port", "radio.port", 1, 65535),
    _S("radio", "step_hz", "number", 10, "send a new frequency only after it moved this much", "radio.step_hz",
       1, 10000),
    _S("radio", "knob_tolerance_hz", "number", 100, "a bigger difference on read-back means the operator retuned "
       "(at least step_hz)", "radio.knob_tolerance_hz", 1, 1e6),
    _S("radio", "enabled", "bool", False, "Doppler tuning on at start (Ctrl+D in the console toggles it)",
       "radio.enabled"),
    # [rotor]
    _S("rotor", "backend", "choice", "none", "\"rotctld\" (Hamlib) or \"sim\" (a simulated rotor)",
       "rotor.backend", choices=("none", "sim", "rotctld")),
    _S("rotor", "host", "host", "127.0.0.1", "rotctld's address", "rotor.host"),
    _S("rotor", "port", "int", 4533, "rotctld's TCP port", "rotor.port", 1, 65535),
    _S("rotor", "geometry", "choice", "north-stop", "north-stop (0..360), south-stop (-180..180) or overlap-450; "
       "\"+flip\" when the elevation rotor reaches 180 (FlipAnts-style inverted passes)", "rotor.geometry",
       choices=ROTOR_GEOMETRIES),
    _S("rotor", "threshold_deg", "number", 2, "move only when the target moved this much (relays wear out)",
       "rotor.threshold_deg", 0, 45),
    _S("rotor", "speed_deg_s", "number", 6, "rotor speed, used to aim ahead by the travel time",
       "rotor.speed_deg_s", 0.1, 90),
    _S("rotor", "max_lead_s", "number", 10, "aim at most this far ahead, seconds", "rotor.max_lead_s", 0, 120),
    _S("rotor", "after_los", "choice", "park", "\"park\", \"next-aos\" (pre-position for the next pass) or \"stay\"",
       "rotor.after_los", choices=("park", "next-aos", "stay")),
    _S("rotor", "flip", "choice", "auto", "inverted tracking: \"auto\" (decided at AOS for the whole pass), "
       "\"on\" (always, FlipAnts 7F) or \"off\" (never, 7E); needs a +flip geometry", "rotor.flip",
       choices=("auto", "on", "off")),
    _S("rotor", "park_azimuth_deg", "int", 0, "park position azimuth, degrees", "rotor.park_azimuth_deg", 0, 359),
    _S("rotor", "park_elevation_deg", "int", 0, "park position elevation, degrees", "rotor.park_elevation_deg",
       0, 90),
    _S("rotor", "park_delay_minutes", "int", 0, "wait this long after LOS before parking; 0 = at once",
       "rotor.park_delay_minutes", 0, 60),
    # [dialects]
    _S("dialects", "dde", "choices", [], "also serve these trackers' DDE interfaces", "dialects.dde",
       choices=("orbitron", "wxtrack", "satpc32"), example=["orbitron", "satpc32"]),
    _S("dialects", "predict_udp", "bool", False, "PREDICT's UDP protocol, for Linux programs written for PREDICT",
       "dialects.predict_udp"),
    _S("dialects", "predict_host", "host", "127.0.0.1", "address PREDICT UDP listens on; anything but loopback "
       "exposes it (its replies are larger than the requests) and is warned about", "dialects.predict_host"),
    _S("dialects", "predict_port", "int", 1210, "PREDICT UDP port (0 = any free port)", "dialects.predict_port",
       0, 65535),
    _S("dialects", "callsign", "text", "NFWSERVER", "reported by PREDICT's GET_QTH", "dialects.callsign", hi=12),
    # [tcp]
    _S("tcp", "enabled", "bool", False, "serve Nova's TCP protocol", "tcp.enabled"),
    _S("tcp", "host", "host", "127.0.0.1", "address to listen on; anything but loopback is warned about",
       "tcp.host"),
    _S("tcp", "port", "int", 8090, "TCP port (Nova's default 8090; 0 = any free port)", "tcp.port", 0, 65535),
    _S("tcp", "allow", "networks", ["127.0.0.1", "::1"], "addresses or networks allowed to connect "
       "(\"192.168.1.20\", \"10.0.0.0/8\", \"::1\"); others are refused", "tcp.allow"),
    _S("tcp", "max_clients", "int", 256, "connections served at once; the next gets a refusal line",
       "tcp.max_clients", 1, 4096),
    _S("tcp", "max_per_address", "int", 32, "connections one address may hold, so that no address locks the "
       "others out", "tcp.max_per_address", 1, 4096),
    _S("tcp", "idle_timeout_s", "number", 300, "close a connection that completes no line for this long, "
       "seconds (WATCH subscribers are never idle)", "tcp.idle_timeout_s", 5, 86400),
    # [easycomm]
    _S("easycomm", "enabled", "bool", False, "write EasyComm I lines to a serial port", "easycomm.enabled"),
    _S("easycomm", "device", "device", None, "serial device (required when enabled)", "easycomm.device",
       hi=4096, example="/dev/ttyUSB0"),
    _S("easycomm", "baud", "choice", 9600, "serial speed", "easycomm.baud", choices=STANDARD_BAUD_RATES),
    _S("easycomm", "rate_hz", "number", 2, "lines per second", "easycomm.rate_hz", 0.5, 10),
    _S("easycomm", "uplink", "choice", "range-rate", "\"range-rate\" (Nova: range rate in UP, zeros in DN, "
       "XXX modes) or \"doppler\" (the channel's corrected frequencies and modes)", "easycomm.uplink",
       choices=("range-rate", "doppler")),
    # [autotrack]
    _S("autotrack", "enabled", "bool", False, "select the satellite of the schedule by itself from the start "
       "(AUTO ON); any accepted SAT= switches it off", "autotrack.enabled"),
    _S("autotrack", "satellites", "satellites", None, "the satellites to work, highest priority first: catalog "
       "numbers or names as SAT= takes them (default: [satellites] favourites)", "autotrack.satellites",
       hi=1000, example=[25544, "SO-50", 43017]),
    _S("autotrack", "min_el_deg", "number", 10, "a pass counts when its highest elevation reaches this, degrees",
       "autotrack.min_el_deg", 0, 90),
    _S("autotrack", "min_gap_s", "number", 60, "the rotor's time to turn round: passes closer than this count as "
       "overlapping, seconds", "autotrack.min_gap_s", 0, 3600),
    # [web]
    _S("web", "enabled", "bool", False, "serve the web dashboard (`nfwserver run --web` for one run)", "web.enabled"),
    _S("web", "host", "host", "127.0.0.1", "address to listen on; anything but loopback is warned about",
       "web.host"),
    _S("web", "port", "int", 8091, "HTTP port (0 = any free port)", "web.port", 0, 65535),
    _S("web", "allow", "networks", ["127.0.0.1", "::1"], "addresses or networks allowed to connect, as [tcp] allow",
       "web.allow"),
    _S("web", "hostnames", "texts", [], "further host names the page is reached by (e.g. \"station.lan\"); "
       "besides these, only the host above, localhost and the address connected to are answered (DNS rebinding)",
       "web.hostnames", hi=253),
    _S("web", "control", "bool", False, "let the page send TUNE, TRACK and SAT (each request needs the token)",
       "web.control"),
    _S("web", "token", "text", None, "the secret every control request must carry (required when control is on; "
       "at least 8 characters, no spaces, not guessable; `config init` writes a fresh one)", "web.token", 8, 256,
       example="change-me-0123"),
)
del _S

SECTION_NAMES: tuple[str, ...] = tuple(s.name for s in SECTIONS)
_BY_NAME: dict[tuple[str, str], Setting] = {(s.section, s.key): s for s in SETTINGS}


def setting(section: str, key: str) -> Setting:
    """The table entry for ``[section] key``; KeyError if there is none."""
    return _BY_NAME[(section, key)]


def keys_of(section: str) -> tuple[str, ...]:
    """The valid keys of ``section``, in table order."""
    return tuple(s.key for s in SETTINGS if s.section == section)


def default(section: str, key: str) -> Any:
    """The server's value of ``[section] key`` when the file leaves it out (None: not set)."""
    entry = _BY_NAME[(section, key)]
    return None if entry.default is None else convert(entry, entry.default, None)
