"""Rotor backend for Hamlib's ``rotctld``: ``P az el`` to point, ``p`` to read back, ``S`` to stop.

Angles are sent in the rotor's frame, already mapped into its range (the daemon's own limits, as set
by ``--set-conf=min_az=..,max_az=..,min_el=..,max_el=..``, must match the configured geometry).
Connection handling, timeouts and back-off are :class:`nfwserver.hamlib.connection.HamlibConnection`'s;
positions read back are checked (finite, within the range) and a bad one counts as a device fault.
"""

from __future__ import annotations

import math

from nfwserver.clock import Clock
from nfwserver.hamlib.commands import GET_POSITION, SET_POSITION, STOP_ROTOR, HamlibCommand
from nfwserver.hamlib.connection import HamlibConnection, HamlibError, HamlibUnavailable
from nfwserver.health import LinkHealth
from nfwserver.rotor.backend import RotorError, RotorUnavailable
from nfwserver.rotor.geometry import RotorGeometry

#: How far (degrees) a reported position may lie outside the configured range before it is refused.
POSITION_SLACK_DEG = 5.0


class RotctldBackend:
    def __init__(self, clock: Clock, geometry: RotorGeometry, host: str = "127.0.0.1", port: int = 4533,
                 timeout_s: float = 1.0, health: LinkHealth | None = None) -> None:
        self.geometry = geometry
        self.connection = HamlibConnection(host, port, clock, name="rotctld", timeout_s=timeout_s, health=health)

    def _do(self, command: HamlibCommand, *args: object) -> list[str]:
        try:
            return self.connection.call(command, *args)
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
        self._do(SET_POSITION, f"{azimuth_deg:.2f}", f"{elevation_deg:.2f}")

    def get_position(self) -> tuple[float, float]:
        """The rotor's position (rotor frame, degrees); a non-finite or out-of-range reply is a device fault.

        A reply may lie up to :data:`POSITION_SLACK_DEG` outside the configured range (rotors
        overshoot their stops a little); anything further is refused, as is anything not a number.
        """
        az_text, el_text = self._do(GET_POSITION)
        try:
            az, el = float(az_text), float(el_text)
        except ValueError:
            az = el = math.nan
        g, slack = self.geometry, POSITION_SLACK_DEG
        if not (g.az_min - slack <= az <= g.az_max + slack and g.el_min - slack <= el <= g.el_max + slack):
            raise RotorError(str(self.connection.fault(f"position {az_text[:20]!r} {el_text[:20]!r} is not a "
                                                       "finite position within the rotor's range")))
        return az, el

    def stop(self) -> None:
        self._do(STOP_ROTOR)

    def close(self) -> None:
        self.connection.close()
