"""What the driver model needs from a rotor, and the errors a backend reports.

Angles are the rotor's own frame (see :mod:`nfwserver.rotor.geometry`): azimuth may exceed 360 on
an overlap rotor, elevation may exceed 90 on a flip rotor.
"""

from __future__ import annotations

from typing import Protocol


class RotorError(Exception):
    """The rotor refused a command (out of range, stalled ...)."""


class RotorUnavailable(RotorError):
    """The rotor (card, daemon) cannot be reached now; the backend retries by itself later."""


class RotorBackend(Protocol):
    def set_position(self, azimuth_deg: float, elevation_deg: float) -> None: ...

    def get_position(self) -> tuple[float, float]: ...

    def stop(self) -> None: ...

    def close(self) -> None: ...
