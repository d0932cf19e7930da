"""Rotor backend for Hamlib's ``rotctld``: ``P az el`` to point, ``p`` to read back, ``S`` to stop.

Angles are sent in the rotor's frame, already mapped into its range (the daemon's own limits, as set
by ``--set-conf=min_az=..,max_az=..,min_el=..,max_el=..``, must match the configured geometry).
Connection handling, timeouts and back-off are :class:`nfwserver.hamlib.connection.HamlibConnection`'s.
"""

from __future__ import annotations

import math

from nfwserver.clock import Clock
from nfwserver.hamlib.connection import HamlibConnection, HamlibError, HamlibUnavailable
from nfwserver.rotor.backend import RotorError, RotorUnavailable
from nfwserver.rotor.geometry import RotorGeometry


class RotctldBackend:
    def __init__(self, clock: Clock, geometry: RotorGeometry, host: str = "127.0.0.1", port: int = 4533,
                 timeout_s: float = 1.0) -> None:
        self.geometry = geometry
        self.connection = HamlibConnection(host, port, clock, name="rotctld", timeout_s=timeout_s)

    def _do(self, command: str, lines: int = 0) -> list[str]:
        try:
            return self.connection.transact(command, lines)
        except HamlibUnavailable as exc:
            raise RotorUnavailable(str(exc)) from None
        except HamlibError as exc:
            raise RotorError(str(exc)) from None

    def set_position(self, azimuth_deg: float, elevation_deg: float) -> None:
        g = self.geometry
        if not all(math.isfinite(v) for v in (azimuth_deg, elevation_deg)) or not (
            g.az_min - 1e-6 <= azimuth_deg <= g.az_max + 1e-6 and g.el_min - 1e-6 <= elevation_deg <= g.el_max + 1e-6
        ):
            raise RotorError(f"({azimuth_deg:.2f}, {elevation_deg:.2f}) is outside the rotor's range")
        self._do(f"P {azimuth_deg:.2f} {elevation_deg:.2f}")

    def get_position(self) -> tuple[float, float]:
        az, el = self._do("p", 2)
        try:
            return float(az), float(el)
        except ValueError:
            raise RotorError(f"rotctld answered {az!r} {el!r} to 'p'") from None

    def stop(self) -> None:
        self._do("S")

    def close(self) -> None:
        self.connection.close()
