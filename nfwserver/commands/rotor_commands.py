"""The commands that act on the rotor (``FLIP``, ``PARK``), run the same way for every face that takes them.

A face parses the line through the table (:func:`nfwserver.commands.parsing.parse_line`); when the entry's
target is :attr:`~nfwserver.commands.table.Target.ROTOR` it hands the result here with the station's rotor
port (None when no rotor is configured) and gets back None (done) or the refusal reason.
"""

from __future__ import annotations

from typing import Protocol

from nfwserver.commands.parsing import Parsed

__all__ = ["NO_ROTOR", "RotorControl", "TrackSwitch", "run_rotor_command"]

NO_ROTOR = "no rotor is configured"


class RotorControl(Protocol):
    """What the rotor commands need of the rotor coupling (any thread may call these)."""

    def set_flip_mode(self, mode: str) -> None: ...

    def request_park(self) -> None: ...


class TrackSwitch(Protocol):
    """What ``PARK`` needs of the station core: tracking switched off, so the rotor stays parked."""

    def set_track(self, on: bool, source: str = ...) -> str | None: ...


def run_rotor_command(parsed: Parsed, rotor: RotorControl | None, core: TrackSwitch, source: str) -> str | None:
    """Run ``FLIP``/``PARK`` from ``source``; None when done, else why not (no rotor configured)."""
    if rotor is None:
        return NO_ROTOR
    word = parsed.command.word
    if word == "FLIP":
        rotor.set_flip_mode(str(parsed.value))
    elif word == "PARK":
        core.set_track(False, source)
        rotor.request_park()
    else:  # a rotor entry without a runner here
        raise AssertionError(f"no runner for the rotor command {word}")
    return None
