"""The validated configuration, as plain records (units in the field names)."""

from __future__ import annotations

from dataclasses import dataclass, field

from nfwserver.radio.transponder import Channel
from nfwserver.tracking.horizon import HorizonTable
from nfwserver.tracking.observer import Observer

#: Used when no observer is configured (the Royal Observatory, Greenwich), with a warning.
DEFAULT_OBSERVER = Observer(51.4779, -0.0015, 46.0)


@dataclass(frozen=True)
class ElementsConfig:
    files: tuple[str, ...] = ()  #: element files, read at start and on every refresh
    urls: tuple[str, ...] = ()  #: element URLs (http/https)
    refresh_hours: float = 24.0  #: 0 disables the periodic refresh
    use_bundled: bool = True  #: include the bundled amateur and weather satellites
    store: str | None = "default"  #: stored catalog file (``elements update``); "default": user data dir; None: off


@dataclass(frozen=True)
class ServerConfig:
    rate_hz: float = 5.0
    services: tuple[str, ...] = ("NFW32", "NFW_SERVER")
    topic: str = "NFW_DATA"
    items: tuple[str, ...] = ("NFW_SERVER", "NFW_DATA")
    satellite: int | None = 25544  #: AutoTracking satellite at start (catalog number)
    ut1_utc_s: float = 0.0


@dataclass(frozen=True)
class RadioConfig:
    backend: str = "none"  #: "none" or "rigctld"
    host: str = "127.0.0.1"
    port: int = 4532
    step_hz: float = 10.0
    knob_tolerance_hz: float = 100.0
    enabled: bool = False  #: Doppler tuning on at start (switchable at run time)


@dataclass(frozen=True)
class RotorConfig:
    backend: str = "none"  #: "none", "sim" or "rotctld"
    host: str = "127.0.0.1"
    port: int = 4533
    geometry: str = "north-stop"  #: a RotorGeometry preset, optionally "+flip"
    threshold_deg: float = 2.0
    speed_deg_s: float = 6.0
    max_lead_s: float = 10.0
    after_los: str = "park"  #: "park", "next-aos" or "stay"
    flip: str = "auto"  #: "auto" or "off"
    park_azimuth_deg: int = 0
    park_elevation_deg: int = 0
    park_delay_minutes: int = 0


@dataclass(frozen=True)
class DialectsConfig:
    dde: tuple[str, ...] = ()  #: other trackers' DDE interfaces to serve: "orbitron", "wxtrack", "satpc32"
    predict_udp: bool = False  #: PREDICT's UDP protocol
    predict_host: str = "127.0.0.1"
    predict_port: int = 1210
    callsign: str = "NFWSERVER"


@dataclass(frozen=True)
class Config:
    observer: Observer = DEFAULT_OBSERVER
    observer_configured: bool = False
    horizon: HorizonTable = field(default_factory=HorizonTable)
    elements: ElementsConfig = field(default_factory=ElementsConfig)
    server: ServerConfig = field(default_factory=ServerConfig)
    dde_names: dict[int, str] = field(default_factory=dict)  #: catalog number -> DDE name override
    favourites: tuple[int, ...] = ()  #: satellites whose passes the console lists
    radio: RadioConfig = field(default_factory=RadioConfig)
    rotor: RotorConfig = field(default_factory=RotorConfig)
    dialects: DialectsConfig = field(default_factory=DialectsConfig)
    state_file: str | None = "default"  #: session state file; "default": user state dir; None: not kept
    channels: dict[int, Channel] = field(default_factory=dict)  #: catalog number -> radio channel
    source: str = "<built-in defaults>"
