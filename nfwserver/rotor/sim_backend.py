"""A simulated rotor on an injected clock: per-axis speed, limits, stall and card-absent injection.

Position is computed from the clock when asked (no thread): each axis moves from where it was at
the last command towards the target at its speed (degrees per second).  Injected faults: a stalled
axis stops moving and reports it (:meth:`SimulatedRotor.stalled_axes`); an axis with speed 0 stops
moving without reporting anything (a jammed rotor with no stall sensing); an absent card makes every call fail with
:class:`RotorUnavailable`.
"""

from __future__ import annotations

from nfwserver.clock import Clock
from nfwserver.rotor.backend import RotorError, RotorUnavailable
from nfwserver.rotor.geometry import RotorGeometry

#: accepted targets the simulated rotor remembers (at least; trimmed to this when twice as many)
COMMANDS_KEPT = 10_000


class SimulatedRotor:
    def __init__(self, clock: Clock, geometry: RotorGeometry | None = None, az_speed_deg_s: float = 6.0,
                 el_speed_deg_s: float = 6.0, start: tuple[float, float] = (0.0, 0.0)) -> None:
        self.clock = clock
        self.geometry = geometry or RotorGeometry()
        self.az_speed, self.el_speed = az_speed_deg_s, el_speed_deg_s
        self._az, self._el = start
        self._target = start
        self._t = clock.monotonic()
        self.card_absent = False
        self.az_stalled = False
        self.el_stalled = False
        #: the accepted set_position calls, in order: the last :data:`COMMANDS_KEPT` to :data:`2 * COMMANDS_KEPT`
        #: (a simulated station running for weeks keeps a bounded record)
        self.commands: list[tuple[float, float]] = []

    def _advance(self) -> None:
        now = self.clock.monotonic()
        dt = max(0.0, now - self._t)
        self._t = now
        if not self.az_stalled:
            self._az = _approach(self._az, self._target[0], self.az_speed * dt)
        if not self.el_stalled:
            self._el = _approach(self._el, self._target[1], self.el_speed * dt)

    def _check(self) -> None:
        if self.card_absent:
            raise RotorUnavailable("simulated rotor: interface card absent")

    def set_position(self, azimuth_deg: float, elevation_deg: float) -> None:
        self._check()
        g = self.geometry
        in_az = g.az_min - 1e-9 <= azimuth_deg <= g.az_max + 1e-9
        if not in_az or not g.el_min - 1e-9 <= elevation_deg <= g.el_max + 1e-9:
            raise RotorError(f"simulated rotor: ({azimuth_deg:.1f}, {elevation_deg:.1f}) is out of range")
        self._advance()
        self._target = (azimuth_deg, elevation_deg)
        self.commands.append(self._target)
        if len(self.commands) > 2 * COMMANDS_KEPT:
            del self.commands[:-COMMANDS_KEPT]

    def get_position(self) -> tuple[float, float]:
        self._check()
        self._advance()
        return self._az, self._el

    def stalled_axes(self) -> tuple[bool, bool]:
        """(azimuth, elevation) stalled: the injected faults, as a controller that senses a stall reports them."""
        return self.az_stalled, self.el_stalled

    @property
    def target(self) -> tuple[float, float]:
        return self._target

    def stop(self) -> None:
        self._check()
        self._advance()
        self._target = (self._az, self._el)

    def close(self) -> None:
        pass


def _approach(value: float, target: float, max_step: float) -> float:
    if abs(target - value) <= max_step:
        return target
    return value + max_step if target > value else value - max_step
