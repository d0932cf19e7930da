"""Radio backend for Hamlib's ``rigctld``: receive on VFO A (``F``/``f``), transmit on the split VFO (``I``/``i``).

Frequencies are validated here (100 kHz .. 300 GHz, integers) because the dummy rig and some
real ones accept anything; frequencies read back are checked the same way, and a bad one counts
as a device fault.  Connection handling, timeouts and back-off are
:class:`nfwserver.hamlib.connection.HamlibConnection`'s.
"""

from __future__ import annotations

import math

from nfwserver.channels.channel import MAX_FREQUENCY_HZ, MIN_FREQUENCY_HZ
from nfwserver.channels.modes import HAMLIB_MODES
from nfwserver.clock import Clock
from nfwserver.hamlib.commands import (
    GET_FREQUENCY,
    GET_SPLIT_FREQUENCY,
    SET_FREQUENCY,
    SET_MODE,
    SET_SPLIT_FREQUENCY,
    SET_SPLIT_MODE,
    SET_SPLIT_VFO,
    HamlibCommand,
)
from nfwserver.hamlib.connection import HamlibConnection, HamlibError, HamlibUnavailable
from nfwserver.health import LinkHealth
from nfwserver.radio.backend import RadioError, RadioUnavailable


def _check_hz(hz: int) -> int:
    value = int(round(hz))
    if not MIN_FREQUENCY_HZ <= value <= MAX_FREQUENCY_HZ:
        raise RadioError(f"frequency {hz} Hz is outside 100 kHz..300 GHz")
    return value


class RigctldBackend:
    """A transceiver behind ``rigctld`` at ``host:port`` (127.0.0.1 unless configured otherwise)."""

    def __init__(self, clock: Clock, host: str = "127.0.0.1", port: int = 4532, timeout_s: float = 1.0,
                 health: LinkHealth | None = None) -> None:
        self.connection = HamlibConnection(host, port, clock, name="rigctld", timeout_s=timeout_s, health=health)

    def _do(self, command: HamlibCommand, *args: object) -> list[str]:
        try:
            return self.connection.call(command, *args)
        except HamlibUnavailable as exc:
            raise RadioUnavailable(str(exc)) from None
        except HamlibError as exc:
            raise RadioError(str(exc)) from None

    def _get_hz(self, command: HamlibCommand) -> int:
        """A frequency read back (Hz); non-finite or outside 100 kHz..300 GHz is a device fault."""
        (line,) = self._do(command)
        try:
            value = float(line)
        except ValueError:
            value = math.nan
        if not MIN_FREQUENCY_HZ <= value <= MAX_FREQUENCY_HZ:
            raise RadioError(str(self.connection.fault(f"{line[:20]!r} to '{command.letter}' is not a frequency "
                                                       "within 100 kHz..300 GHz")))
        return int(value)

    def set_rx_frequency(self, hz: int) -> None:
        self._do(SET_FREQUENCY, _check_hz(hz))

    def get_rx_frequency(self) -> int:
        return self._get_hz(GET_FREQUENCY)

    def set_tx_frequency(self, hz: int) -> None:
        self._do(SET_SPLIT_FREQUENCY, _check_hz(hz))

    def get_tx_frequency(self) -> int:
        return self._get_hz(GET_SPLIT_FREQUENCY)

    def set_split(self, on: bool) -> None:
        self._do(SET_SPLIT_VFO, 1 if on else 0, "VFOB")

    def set_modes(self, rx_mode: str, tx_mode: str | None) -> None:
        for mode in (rx_mode, tx_mode):
            if mode is not None and mode.upper() not in HAMLIB_MODES:
                raise RadioError(f"mode {mode!r} is not a Hamlib mode")
        self._do(SET_MODE, rx_mode.upper(), 0)
        if tx_mode is not None:
            self._do(SET_SPLIT_MODE, tx_mode.upper(), 0)

    def close(self) -> None:
        self.connection.close()
