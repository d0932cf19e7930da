"""The validated configuration, as plain records (units in the field names).

Every default comes from the configuration table (:mod:`nfwserver.config.table`) through
:func:`~nfwserver.config.table.default`; ``Config()`` is exactly what an empty file means.
"""

from __future__ import annotations

import ipaddress
from dataclasses import dataclass, field

from nfwserver.channels.channel import Channel
from nfwserver.config.table import default
from nfwserver.tracking.horizon import HorizonTable
from nfwserver.tracking.observer import Observer

#: Used when no observer is configured (the Royal Observatory, Greenwich), with a warning.
DEFAULT_OBSERVER = Observer(51.4779, -0.0015, 46.0)


@dataclass(frozen=True)
class ElementsConfig:
    files: tuple[str, ...] = default("elements", "files")  #: element files, read at start and on every refresh
    urls: tuple[str, ...] = default("elements", "urls")  #: element URLs (http/https)
    sources: tuple[str, ...] = default("elements", "sources")  #: named sources (config.element_presets)
    preset_mirror: str | None = default("elements", "preset_mirror")  #: base URL replacing the presets' sites
    refresh_hours: float = default("elements", "refresh_hours")  #: 0 disables the periodic refresh
    use_bundled: bool = default("elements", "use_bundled")  #: include the bundled amateur and weather satellites
    #: stored catalog file (``elements update``); "default": user data dir; None: off
    store: str | None = default("elements", "store")
    max_source_mib: float = default("elements", "max_source_mib")  #: largest file or download, MiB
    max_source_sets: int = default("elements", "max_source_sets")  #: most element sets in one source
    stale_days: float = default("elements", "stale_days")  #: sets older than this are flagged as stale


@dataclass(frozen=True)
class ServerConfig:
    rate_hz: float = default("server", "rate_hz")
    services: tuple[str, ...] = default("server", "services")
    topic: str = default("server", "topic")
    items: tuple[str, ...] = default("server", "items")
    #: AutoTracking satellite at start: a catalog number, or a name as SAT= takes it (resolved at start)
    satellite: int | str | None = default("server", "satellite")
    ut1_utc_s: float = default("server", "ut1_utc_s")
    tune: bool = default("server", "tune")  #: DDE output on at start (as a ``TUNE ON`` poke)
    track: bool = default("server", "track")  #: autotracking on at start (as a ``TRACK ON`` poke)


@dataclass(frozen=True)
class RadioConfig:
    backend: str = default("radio", "backend")  #: "none" or "rigctld"
    host: str = default("radio", "host")
    port: int = default("radio", "port")
    step_hz: float = default("radio", "step_hz")
    knob_tolerance_hz: float = default("radio", "knob_tolerance_hz")
    enabled: bool = default("radio", "enabled")  #: Doppler tuning on at start (switchable at run time)


@dataclass(frozen=True)
class RotorConfig:
    backend: str = default("rotor", "backend")  #: "none", "sim" or "rotctld"
    host: str = default("rotor", "host")
    port: int = default("rotor", "port")
    geometry: str = default("rotor", "geometry")  #: a RotorGeometry preset, optionally "+flip"
    threshold_deg: float = default("rotor", "threshold_deg")
    speed_deg_s: float = default("rotor", "speed_deg_s")
    max_lead_s: float = default("rotor", "max_lead_s")
    after_los: str = default("rotor", "after_los")  #: "park", "next-aos" or "stay"
    flip: str = default("rotor", "flip")  #: "auto", "on" (always inverted) or "off" (never)
    park_azimuth_deg: int = default("rotor", "park_azimuth_deg")
    park_elevation_deg: int = default("rotor", "park_elevation_deg")
    park_delay_minutes: int = default("rotor", "park_delay_minutes")


@dataclass(frozen=True)
class DialectsConfig:
    dde: tuple[str, ...] = default("dialects", "dde")  #: "orbitron", "wxtrack", "satpc32"
    predict_udp: bool = default("dialects", "predict_udp")  #: PREDICT's UDP protocol
    predict_host: str = default("dialects", "predict_host")
    predict_port: int = default("dialects", "predict_port")
    callsign: str = default("dialects", "callsign")


@dataclass(frozen=True)
class TcpConfig:
    """Nova's TCP server."""

    enabled: bool = default("tcp", "enabled")
    host: str = default("tcp", "host")  #: address listened on
    port: int = default("tcp", "port")
    #: networks allowed to connect, normalised by :mod:`ipaddress` ("127.0.0.1/32", "10.0.0.0/8", "::1/128")
    allow: tuple[str, ...] = default("tcp", "allow")
    max_clients: int = default("tcp", "max_clients")  #: connections at once
    max_per_address: int = default("tcp", "max_per_address")  #: connections from one address at once
    idle_timeout_s: float = default("tcp", "idle_timeout_s")  #: seconds without a complete line (not WATCH)

    @staticmethod
    def peer_key(address: str) -> str:
        """The peer's address as one key per host (:func:`plain_address`)."""
        return plain_address(address)

    def allows(self, address: str) -> bool:
        """True when the peer ``address`` (an IP address string) lies in one of the ``allow`` networks."""
        return address_allowed(self.allow, address)


def plain_address(address: str) -> str:
    """``address`` (an IP address string) in canonical form, without an IPv6 zone, an IPv4-mapped IPv6 address
    as IPv4: one key per host (text that is no address is returned as it is)."""
    try:
        ip = ipaddress.ip_address(address.split("%", 1)[0])
    except ValueError:
        return address
    if isinstance(ip, ipaddress.IPv6Address) and ip.ipv4_mapped is not None:
        return str(ip.ipv4_mapped)
    return str(ip)


def address_allowed(networks: tuple[str, ...], address: str) -> bool:
    """True when ``address`` (an IP address string, IPv4-mapped IPv6 allowed) lies in one of ``networks``."""
    try:
        ip = ipaddress.ip_address(address.split("%", 1)[0])
    except ValueError:
        return False
    if isinstance(ip, ipaddress.IPv6Address) and ip.ipv4_mapped is not None:
        ip = ip.ipv4_mapped
    return any(ip in ipaddress.ip_network(net) for net in networks)


@dataclass(frozen=True)
class WebConfig:
    """The web dashboard (:mod:`nfwserver.web`)."""

    enabled: bool = default("web", "enabled")
    host: str = default("web", "host")  #: address listened on
    port: int = default("web", "port")  #: 0: any free port
    allow: tuple[str, ...] = default("web", "allow")  #: networks allowed to connect (normalised as [tcp] allow)
    hostnames: tuple[str, ...] = default("web", "hostnames")  #: host names the page may be reached by, besides host
    control: bool = default("web", "control")  #: the page may send TUNE/TRACK/SAT
    token: str | None = default("web", "token")  #: required with every control request; always set with control

    def allows(self, address: str) -> bool:
        return address_allowed(self.allow, address)


@dataclass(frozen=True)
class EasyCommConfig:
    """EasyComm I serial output."""

    enabled: bool = default("easycomm", "enabled")
    device: str | None = default("easycomm", "device")  #: e.g. "/dev/ttyUSB0"; always set when enabled
    baud: int = default("easycomm", "baud")
    rate_hz: float = default("easycomm", "rate_hz")  #: lines per second
    uplink: str = default("easycomm", "uplink")  #: "range-rate" (Nova) or "doppler"


@dataclass(frozen=True)
class AutotrackConfig:
    """Unattended operation (:mod:`nfwserver.autotrack`)."""

    enabled: bool = default("autotrack", "enabled")  #: AUTO ON at start
    #: the satellites to work, highest priority first (catalog numbers, or names as SAT= takes them);
    #: None: the [satellites] favourites (:meth:`Config.autotrack_satellites`)
    satellites: tuple[int | str, ...] | None = default("autotrack", "satellites")
    min_el_deg: float = default("autotrack", "min_el_deg")  #: a pass counts when its highest elevation reaches this
    min_gap_s: float = default("autotrack", "min_gap_s")  #: passes closer than this (s) count as overlapping


@dataclass(frozen=True)
class Config:
    observer: Observer = DEFAULT_OBSERVER
    observer_configured: bool = False
    horizon: HorizonTable = field(default_factory=HorizonTable)
    elements: ElementsConfig = field(default_factory=ElementsConfig)
    server: ServerConfig = field(default_factory=ServerConfig)
    dde_names: dict[int, str] = field(default_factory=lambda: default("satellites", "names"))
    #: InstantTrack mode schedules by catalog number (``000B128A``: phases in 256ths, then the mode)
    schedules: dict[int, str] = field(default_factory=lambda: default("satellites", "schedules"))
    favourites: tuple[int, ...] = default("satellites", "favourites")  #: satellites whose passes the console lists
    radio: RadioConfig = field(default_factory=RadioConfig)
    rotor: RotorConfig = field(default_factory=RotorConfig)
    dialects: DialectsConfig = field(default_factory=DialectsConfig)
    #: session state file; "default": user state dir; None: not kept
    state_file: str | None = default("server", "state_file")
    #: catalog number -> radio channel (the built-in ones plus the configured ones)
    channels: dict[int, Channel] = field(default_factory=lambda: default("satellites", "channels"))
    source: str = "<built-in defaults>"  #: the file read, or "<built-in defaults>" / "<config>"
    tcp: TcpConfig = field(default_factory=TcpConfig)
    easycomm: EasyCommConfig = field(default_factory=EasyCommConfig)
    web: WebConfig = field(default_factory=WebConfig)
    autotrack: AutotrackConfig = field(default_factory=AutotrackConfig)
    horizon_file: str | None = None  #: the horizon file read, if the horizon came from one
    path: str | None = None  #: the configuration file actually read; None when none was
    #: accepted but worth saying at start (e.g. a listener reachable from other hosts); the caller logs them
    warnings: tuple[str, ...] = ()

    def autotrack_satellites(self) -> tuple[int | str, ...]:
        """The satellites autotrack works, highest priority first: ``[autotrack] satellites``, else the
        ``[satellites] favourites``."""
        listed = self.autotrack.satellites
        return tuple(self.favourites) if listed is None else listed
