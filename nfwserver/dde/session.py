"""The session state the Nova interface controls: tune/track switches, satellite, antenna position."""

from __future__ import annotations

from dataclasses import dataclass
from datetime import datetime

from nfwserver.tracking.look_angles import LookAngles


@dataclass(frozen=True)
class AntennaPosition:
    """Where the antennas point, as last reported (by an ANTAZ/ANTEL poke or a rotor backend)."""

    azimuth_deg: float | None
    elevation_deg: float | None
    source: str  #: "poke", "rotor", "console", ...
    time: datetime | None


@dataclass(frozen=True)
class TickSample:
    """What one publish tick computed; tick listeners (rotor, radio, console) receive it."""

    time: datetime  #: the instant the values are computed for (aware UTC)
    catalog_number: int | None  #: the AutoTracking satellite, None when none is selected
    dde_name: str | None
    look_angles: LookAngles | None  #: None without a satellite or when SGP4 failed
    above_horizon: bool  #: above the horizon table at the satellite's azimuth
    tune_on: bool
    track_on: bool
    text: str  #: the Nova string published this tick ("" when nothing was published)
    status: int  #: status word (:class:`nfwserver.dde.status.StatusBit`)


@dataclass(frozen=True)
class SessionSnapshot:
    """A consistent copy of the session for display."""

    tune_on: bool
    track_on: bool
    catalog_number: int | None
    dde_name: str | None
    antenna: AntennaPosition
    last_sample: TickSample | None
    status: int
    rate_hz: float
    clients: int  #: open conversations
    advise_loops: int
