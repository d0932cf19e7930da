"""Records that travel from the tracker to the outputs: one tick's results and the antenna position."""

from __future__ import annotations

from dataclasses import dataclass
from datetime import datetime

from nfwserver.core.status import INTERFACE_VERSION, ArithmeticErrorCode
from nfwserver.tracking.look_angles import LookAngles


@dataclass(frozen=True)
class AntennaPosition:
    """Where the antennas point, as last reported (by an ANTAZ/ANTEL command or a rotor read-back).

    Sky azimuth and elevation in degrees (topocentric, azimuth from north through east).
    """

    azimuth_deg: float | None
    elevation_deg: float | None
    source: str  #: "poke", "rotor", "console", ...
    time: datetime | None


@dataclass(frozen=True)
class TickSample:
    """What one tick computed; every output adapter receives it.

    ``look_angles`` are topocentric (azimuth/elevation in degrees, range in km, range rate in km/s,
    positive receding) for ``time``.
    """

    time: datetime  #: the instant the values are computed for (aware UTC)
    catalog_number: int | None  #: the AutoTracking satellite, None when none is selected
    dde_name: str | None
    look_angles: LookAngles | None  #: None without a satellite, station, or when computation failed
    above_horizon: bool  #: above the horizon table at the satellite's azimuth
    feed_on: bool  #: the feed: Nova's TUNE ON (the Nova string is published)
    tracking: bool  #: autotracking enabled (Nova's TRACK ON; OrbitDRV "tracking enabled")
    text: str  #: the Nova string published this tick ("" when nothing was published)
    status: int  #: OrbitDRV-style status word (:class:`nfwserver.core.status.StatusBit`)
    doppler_on: bool = False  #: Doppler updates to the radio (OrbitDRV "tuning enabled"; not Nova's TUNE)
    error: ArithmeticErrorCode = ArithmeticErrorCode.NONE  #: code reported with the arithmetic-error bit
    interface_version: int = INTERFACE_VERSION  #: reported with every status word, as OrbitDRV did
