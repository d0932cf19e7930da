"""The side of the KCT driver that faces the rotor: sending targets, reading back, stalls and their healing.

:class:`KctRotorLink` is the base of :class:`~nfwserver.rotor.kct_driver.KctDriver`; it owns the backend,
the geometry, the current target (KCT frame: elevation -90..269, azimuth 0..359) and the stall watch
(:mod:`~nfwserver.rotor.stall`).  A target is mapped into the rotor's azimuth range continuously from its
last position (a 359 -> 1 step never becomes a 358-degree swing) and sent only when it changed.  A stalled
axis is stopped and held; nothing latches: :meth:`retry_now` (an operator's action) re-arms it at once, and
the driver's service call re-arms it by itself after the ``rotor`` link's back-off (:data:`STALL_BACKOFF`:
5 s doubling to a minute, so a jammed motor is driven for at most one stall timeout a minute).  The stall
is that link's fault from the moment it is declared until the re-armed rotor accepts a command and moves
toward its target (or is found already there).  A single refused move is the link's fault at once (not yet
a stall: three in a row are), cleared the same way.

When the backend cannot be reached (its daemon stopped or restarts), the target is sent again at the first
reading after its return, whether or not it changed meanwhile: a restarted daemon has forgotten it.  A rotor
that is neither where it was sent nor seen moving there is ``off-target`` in :meth:`KctRotorLink.link_state`.

Angles are degrees; rotor-frame positions are what the backend takes and reports.
"""

from __future__ import annotations

import logging

from nfwserver.clock import Clock
from nfwserver.hamlib.connection import daemon_link_ok
from nfwserver.health import Backoff, LinkHealth
from nfwserver.ratelimited_log import RateLimitedLog
from nfwserver.rotor.backend import RotorBackend, RotorError, RotorUnavailable
from nfwserver.rotor.geometry import RotorGeometry
from nfwserver.rotor.kct_annunciator import Annunciator
from nfwserver.rotor.stall import AXES, StallReporting, StallWatch

__all__ = ["STALL_BACKOFF", "KctRotorLink"]

log = logging.getLogger("nfwserver.rotor.kct_driver")

#: When a stalled rotor is tried again by itself: after 5 s, doubling up to once a minute.
STALL_BACKOFF = Backoff(5.0, 60.0)
#: Axes the stall watch follows: azimuth and elevation.
_AXES = 2


class KctRotorLink:
    """The rotor-facing state and calls of the driver; see the module docstring."""

    def __init__(self, clock: Clock, backend: RotorBackend, geometry: RotorGeometry | None,
                 stall_timeout_s: float | None, health: LinkHealth | None) -> None:
        self.clock = clock
        self.backend = backend
        self.geometry = geometry or RotorGeometry()
        #: the ``rotor`` link: failing from a declared stall until the re-armed rotor moves again
        self.health = health if health is not None else LinkHealth("rotor", clock, STALL_BACKOFF, logger=log)
        self.annunciator = Annunciator(clock.now)
        self.stall = StallWatch(timeout_s=stall_timeout_s)
        self._diagnostics = RateLimitedLog(log, clock)
        self._target: tuple[float, float] | None = None  # (el, az) KCT frame
        self._rotor_az: float | None = None  # last commanded rotor-frame azimuth (continuity reference)
        self._sent: tuple[float, float] | None = None
        self._card_absent = False
        self._position: tuple[float, float] | None = None  # rotor frame, last read back
        self._alarmed = False  # the current stall was announced
        #: the backend could not be reached since the target was last sent: its daemon may have restarted
        #: and forgotten the target (a restarted dummy rotctld sits at 0/0), so it is sent again at once
        self._resend = False

    # -- reading back ---------------------------------------------------------------------
    def read_position(self) -> tuple[float, float] | None:
        """Read the rotor back (rotor frame); None when it cannot be reached."""
        try:
            self._position = self.backend.get_position()
            self._card_absent = False
        except RotorUnavailable:
            self._lost()
            return None
        except RotorError as exc:
            self._diagnostics.warning("read", "rotor position read failed: %s", exc)
            self._stalled(self.stall.backend_error(_AXES), f"the rotor refused {self.stall.errors} calls in a row")
            return None
        if isinstance(self.backend, StallReporting):
            self._stalled(self.stall.reported(self.backend.stalled_axes()), "the rotor reports it")
        moving = self.stall.observe(self.clock.monotonic(), self._sent, self._position, _AXES)
        self._stalled(moving, f"no movement toward the target for {self.stall.timeout_s} s")
        if not self.health.ok and not any(self.stall.stalled) and self.stall.errors == 0 and self.stall.progressed:
            self.health.succeeded()  # re-armed, accepted, and moving (or already there): the stall is over
            self._alarmed = False
        if (self._sent is None or self._resend) and self._target is not None:
            self._resend = False
            self._push(force=True)  # the rotor came back: send the target again, at once
        return self._position

    def _lost(self) -> None:
        """The backend cannot be reached: whatever it held may be gone when it returns."""
        self._card_absent = True
        self._resend = True
        self.stall.lost_sight()  # an outage is not a stall: the no-movement timers restart on return

    def rotor_position(self) -> tuple[float, float] | None:
        """Last read-back position, rotor frame."""
        return self._position

    # -- stalls -----------------------------------------------------------------------------
    def _stalled(self, axes: list[int], why: str) -> None:
        if not axes:
            return
        names = " and ".join(AXES[i] for i in axes)
        fault = self.health.failed(f"{names} rotor stalled ({why})")
        if not self._alarmed:  # the alarm marks the start of a stall, not every try that finds it still there
            self._alarmed = True
            self.annunciator.emit("alarm", f"{names} rotor stalled ({why}); held, trying again in "
                                           f"{fault.retry_at - self.clock.monotonic():.0f} s")
        self._stop_rotor()

    def _probe(self, why: str) -> None:
        """Re-arm the stalled axes on probation and send the target again."""
        self._diagnostics.log(logging.INFO, "probe", "rotor: trying the stalled rotor again (%s)", why)
        self.stall.probe()
        self._push(force=True)

    def retry_now(self) -> None:
        """An operator's action (a new satellite, ``TRACK ON``, a flip change): a stalled rotor is re-armed
        and tried at once, whatever its back-off."""
        if any(self.stall.stalled):
            self.health.retry_now()
            self._probe("an operator's action")

    @property
    def commanded_position(self) -> tuple[float, float] | None:
        """The last (azimuth, elevation) the rotor accepted, rotor frame, degrees; None before any."""
        return self._sent

    @property
    def backend_reachable(self) -> bool:
        """False while the backend cannot be reached (KCT status bit 80h, "card absent")."""
        return not self._card_absent

    @property
    def stalled(self) -> bool:
        """Any axis is stalled and held now (status bits 10h/20h)."""
        return any(self.stall.stalled)

    def link_state(self) -> str:
        """The rotor's state in one word, as STATUS, the console and the web page show it: ``unreachable`` (no
        position read back, or the backend cannot be reached), ``stalled``, ``retrying`` (moves refused),
        ``failing`` (its daemon answers slowly or with nonsense), ``off-target`` (neither where it was sent
        nor seen moving there for :attr:`StallWatch.idle_grace_s`, not yet a stall), else ``ok``."""
        if self.rotor_position() is None or not self.backend_reachable:
            return "unreachable"
        if self.stalled:
            return "stalled"
        if not self.health.ok:
            return "retrying"
        if not daemon_link_ok(self.backend):
            return "failing"
        return "off-target" if self.off_target() else "ok"

    def off_target(self) -> bool:
        """The rotor is neither where it was last sent nor moving there (see :meth:`link_state`)."""
        return bool(self.stall.idle_axes(self.clock.monotonic(), self._sent, self._position, _AXES))

    def _stop_rotor(self) -> None:
        try:
            self.backend.stop()
        except RotorUnavailable as exc:
            log.warning("rotor stop failed: %s", exc)
            self._lost()
        except RotorError as exc:
            log.warning("rotor stop failed: %s", exc)

    def _command_for(self, el: float, az: float) -> tuple[float, float] | None:
        """Rotor-frame (az, el) for a KCT target, or None if the rotor cannot reach it."""
        g = self.geometry
        if not g.el_min - 1e-9 <= el <= g.el_max + 1e-9 or not g.rotor_azimuths(az % 360.0):
            return None
        reference = self._rotor_az if self._rotor_az is not None else (self._position[0] if self._position else None)
        return g.nearest_rotor_azimuth(az % 360.0, reference), el

    def _push(self, force: bool = False) -> None:
        if self._target is None:
            return
        command = self._command_for(*self._target)
        if command is None:  # set_target takes only targets this rotor can reach
            return
        stalled, pos = self.stall.stalled, self._position
        if all(stalled[: _AXES]) or (any(stalled) and pos is None):
            return
        rotor_az = pos[0] if stalled[0] and pos is not None else command[0]
        rotor_el = pos[1] if stalled[1] and pos is not None else command[1]
        command = (rotor_az, rotor_el)
        if command == self._sent and not force:
            return
        try:
            self.backend.set_position(rotor_az, rotor_el)
        except RotorUnavailable as exc:
            if not self._card_absent:
                log.warning("rotor unavailable: %s", exc)
            self._lost()
            self._sent = None
            return
        except RotorError as exc:
            # Visible at once on the rotor link; three in a row make a stall (held, retried after back-off).
            self.health.failed(f"the rotor refused a move to ({rotor_az:.1f}, {rotor_el:.1f}): {exc}", attempt=False)
            self.stall.forget_progress()
            self._stalled(self.stall.backend_error(_AXES), f"the rotor refused {self.stall.errors} calls in a row")
            return
        self.stall.backend_ok()
        self._card_absent = False
        self._sent = command
        self._rotor_az = rotor_az
