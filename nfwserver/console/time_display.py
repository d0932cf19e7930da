"""How the console shows instants: UTC or local time, with the zone always named.

InstantTrack starts in UTC and its ``Z`` command toggles between UTC and local time; the zone name
is always part of the displayed time ("03/01/92 06:22:37 UTC", then "02/29/92 23:22:37 PDT").
:class:`TimeDisplay` is that switch.  Instants in are timezone-aware (UTC from the station clock).
"""

from __future__ import annotations

from datetime import datetime, timezone, tzinfo


class TimeDisplay:
    """UTC (the default) or local time; ``local_zone`` defaults to the system's zone."""

    def __init__(self, local_zone: tzinfo | None = None) -> None:
        self.local_zone = local_zone
        self.utc = True

    def toggle(self) -> bool:
        """Switch UTC <-> local; returns True when now showing UTC."""
        self.utc = not self.utc
        return self.utc

    def convert(self, when: datetime) -> datetime:
        """``when`` in the zone shown."""
        if self.utc:
            return when.astimezone(timezone.utc)
        return when.astimezone(self.local_zone) if self.local_zone is not None else when.astimezone()

    def zone(self, when: datetime) -> str:
        """The zone's name at ``when`` ("UTC", "AEST", ...; a UTC offset when the zone has no name)."""
        if self.utc:
            return "UTC"
        local = self.convert(when)
        return local.tzname() or local.strftime("%z")

    def clock(self, when: datetime | None) -> str:
        """``HH:MM:SS`` in the zone shown (the zone is named elsewhere on the same line or pane)."""
        return self.convert(when).strftime("%H:%M:%S") if when is not None else "--:--:--"

    def short(self, when: datetime | None) -> str:
        """``HH:MM`` in the zone shown."""
        return self.convert(when).strftime("%H:%M") if when is not None else "--:--"

    def date(self, when: datetime | None) -> str:
        """``MM-DD`` in the zone shown."""
        return self.convert(when).strftime("%m-%d") if when is not None else "--"

    def stamp(self, when: datetime) -> str:
        """``MM-DD HH:MM:SS ZONE``."""
        return f"{self.convert(when):%m-%d %H:%M:%S} {self.zone(when)}"
