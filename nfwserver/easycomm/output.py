"""EasyComm I output on a serial port: the rotor controller's view of the tracked satellite.

:class:`EasyCommOutput` is a tick listener that only records the newest sample
(:meth:`EasyCommOutput.on_tick`, on the publisher thread, never blocks).  Its own thread,
``nfw-easycomm``, wakes ``rate_hz`` times a second *on the injected clock* and writes one line
(:mod:`nfwserver.easycomm.line_format`) for the newest sample, with pyserial.  Nova never reads the
port, and neither do we.

Only the current tick is written: a sample older than one and a half periods (the longer of the
publisher's and this output's) is skipped, not written.  After the process was stopped and continued
(SIGSTOP/SIGCONT, a suspended VM) the worker may wake before the publisher has ticked again; the
newest sample then describes an instant seconds or minutes ago, and the antenna must not be sent
there.  The next period writes the fresh tick.

When lines are written: while autotracking is on (Nova's ``TRACK ON``) and the selected satellite
is above the horizon table (``AH:Y``).  When that stops -- ``TRACK OFF``, LOS, another satellite
below the horizon, no position -- one ``SA SE`` line stops the antenna; ``SA SE`` is written again at
shutdown (:meth:`stop`) whenever the port can be written.

The device may vanish and return (a USB adapter unplugged): a failed open or write closes the port
and the worker tries again after 1 s, 2 s, 4 s ... at most ``max_backoff_s``, measured on the clock,
through the station's ``easycomm`` link (:class:`~nfwserver.health.LinkHealth`): the fault is in
STATUS while it lasts, its first failure is logged as a warning, and the first successful write clears it.
Writes time out after :data:`WRITE_TIMEOUT_S` real seconds (a port nobody drains), so the worker never hangs; the
publisher is never involved.

Threading: the worker thread owns the port; :meth:`stop` joins it before the final ``SA SE``.
``last_line`` (the last line written, for the console), ``connected`` and ``lines_written`` may be
read from any thread.
"""

from __future__ import annotations

import logging
from collections.abc import Callable

import serial

from nfwserver.clock import Clock
from nfwserver.config.schema import EasyCommConfig
from nfwserver.core.sample import TickSample
from nfwserver.core.service_thread import ServiceThread
from nfwserver.core.state import StationState
from nfwserver.easycomm.line_format import LINE_END, STOP_LINE, doppler_line, range_rate_line
from nfwserver.health import Backoff, LinkHealth

log = logging.getLogger(__name__)

WRITE_TIMEOUT_S = 1.0
PortOpener = Callable[[str, int], serial.Serial]


def open_serial(device: str, baud: int) -> serial.Serial:
    """The port as a controller expects it: 8N1, no flow control, writes that time out."""
    return serial.Serial(device, baud, timeout=0, write_timeout=WRITE_TIMEOUT_S)


class EasyCommOutput(ServiceThread):
    """See the module docstring.  ``state`` supplies the channels for ``uplink = "doppler"``."""

    thread_name = "nfw-easycomm"

    def __init__(self, config: EasyCommConfig, state: StationState, clock: Clock, *, max_backoff_s: float = 16.0,
                 open_port: PortOpener = open_serial, health: LinkHealth | None = None) -> None:
        if not config.device:
            raise ValueError("[easycomm] device is required")
        self.config = config
        self.state = state
        self.clock = clock
        self.open_port = open_port
        #: the port's health: failing while it cannot be opened or written (its own when none is given)
        self.health = health if health is not None else LinkHealth("easycomm", clock, Backoff(1.0, max_backoff_s),
                                                                   logger=log)
        self.last_line = ""  #: the last line written, without its terminator
        self.lines_written = 0
        self.stale_skipped = 0  #: periods skipped because the newest sample was not the current tick
        self._port: serial.Serial | None = None
        self._pending: TickSample | None = None
        self._active = False  # the last step wrote a position: a stop is owed when it ends
        self._opened_once = False
        super().__init__()

    @property
    def connected(self) -> bool:
        return self._port is not None

    # -- publisher side ------------------------------------------------------------------------------
    def on_tick(self, sample: TickSample) -> None:
        """Tick listener: remember the newest sample."""
        self._pending = sample

    # -- what to write -------------------------------------------------------------------------------
    def line_for(self, sample: TickSample | None) -> str | None:
        """The line for ``sample``, or None when the antenna should not follow it."""
        if sample is None or not sample.tracking or sample.look_angles is None or not sample.above_horizon:
            return None
        la = sample.look_angles
        if self.config.uplink == "doppler":
            channel = self.state.channels.get(sample.catalog_number) if sample.catalog_number is not None else None
            return doppler_line(la.azimuth_deg, la.elevation_deg, la.range_rate_km_s, channel)
        return range_rate_line(la.azimuth_deg, la.elevation_deg, la.range_rate_km_s)

    def max_sample_age_s(self) -> float:
        """How old (seconds, on the clock) the newest sample may be and still be the current tick."""
        return 1.5 * max(1.0 / self.state.rate_hz, 1.0 / self.config.rate_hz)

    def step(self) -> None:
        """One period's work: a position line, or the one stop line owed (worker thread).  A closed port is
        reopened (within the back-off) even with nothing to write, so a missing device shows at once."""
        if self._port is None:
            self._open()
        sample = self._pending
        if sample is not None and (self.clock.now() - sample.time).total_seconds() > self.max_sample_age_s():
            self.stale_skipped += 1
            return  # computed for another tick: wait for the current one
        line = self.line_for(sample)
        if line is not None:
            if self._write(line):
                self._active = True
        elif self._active and self._write(STOP_LINE):
            self._active = False

    # -- the port ---------------------------------------------------------------------------------------
    def _open(self) -> bool:
        if self._port is not None:
            return True
        if not self.health.may_try():
            return False
        device = str(self.config.device)
        try:
            self._port = self.open_port(device, self.config.baud)
        except (serial.SerialException, OSError, ValueError) as exc:
            self.health.failed(f"cannot open {device}: {exc}")
            return False
        if not self._opened_once:
            log.info("EasyComm I output on %s at %d baud", device, self.config.baud)
        self._opened_once = True
        return True

    def _close(self) -> None:
        port, self._port = self._port, None
        if port is not None:
            try:
                port.close()
            except (serial.SerialException, OSError):
                pass

    def _write(self, line: str) -> bool:
        if not self._open():
            return False
        assert self._port is not None
        try:
            self._port.write((line + LINE_END).encode("ascii"))
        except (serial.SerialException, OSError) as exc:
            self._close()
            self.health.failed(f"writing to {self.config.device} failed: {exc}")
            return False
        self.health.succeeded()
        self.last_line = line
        self.lines_written += 1
        return True

    # -- life cycle -----------------------------------------------------------------------------------
    def _run(self) -> None:
        period = 1.0 / self.config.rate_hz
        due = self.clock.monotonic()
        while not self._stop.is_set():
            try:
                self.step()
            except Exception:  # keep writing whatever happens
                log.exception("EasyComm output failed")
            due += period  # a fixed schedule on the clock, so late wake-ups do not slow the rate
            now = self.clock.monotonic()
            if now - due > period:  # fell behind (a slow write): go on from now rather than burst
                due = now
            if self.clock.wait(self._stop, due - now):
                break

    def stop(self) -> None:
        """Stop the worker, write ``SA SE`` (if the port can be written) and close the port."""
        self._stop.set()
        if self._thread is None:
            return
        self._thread.join(5.0)
        self._thread = None
        self.health.retry_now()  # one last try for the stop line, whatever the back-off
        self._write(STOP_LINE)
        self._active = False
        self._close()
