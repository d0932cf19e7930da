"""The KCT driver's rotor parking (service call 14h): parameters and the park timer.

"BX=Parking delay time in minutes; (0 to 60; 0 means disable parking function) / CX=Park-position
azimuth (0-359) / DX=Park-position elevation (0-90)".  Setting the parameters stops a running timer.
Times are aware UTC datetimes from the driver's clock.
"""

from __future__ import annotations

from dataclasses import dataclass
from datetime import datetime, timedelta


@dataclass(frozen=True)
class ParkingParameters:
    delay_minutes: int  #: 0..60; 0 disables parking
    azimuth_deg: int  #: 0..359
    elevation_deg: int  #: 0..90


class Parking:
    def __init__(self) -> None:
        self.parameters = ParkingParameters(0, 0, 0)
        self._started: datetime | None = None

    def set(self, delay_minutes: int, azimuth_deg: int, elevation_deg: int) -> bool:
        """SET PARAMETERS (AL=01h); False (and nothing changed) when a value is out of range."""
        if not (0 <= delay_minutes <= 60 and 0 <= azimuth_deg <= 359 and 0 <= elevation_deg <= 90):
            return False
        self.parameters = ParkingParameters(delay_minutes, azimuth_deg, elevation_deg)
        self._started = None
        return True

    def start(self, now: datetime) -> None:
        """START PARKING TIMER (AL=03h); nothing when parking is disabled (delay 0)."""
        if self.parameters.delay_minutes > 0:
            self._started = now

    def stop(self) -> None:
        """STOP PARKING TIMER (AL=02h)."""
        self._started = None

    def due(self, now: datetime) -> bool:
        """True once when the timer has run its delay (the timer then stops)."""
        if self._started is None or self.parameters.delay_minutes <= 0:
            return False
        if now - self._started < timedelta(minutes=self.parameters.delay_minutes):
            return False
        self._started = None
        return True
