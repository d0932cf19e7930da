"""The rotor commands (``FLIP``, ``PARK``) run for a caller that holds its own rotor port.

Every face hands its parsed commands to the station core
(:meth:`nfwserver.core.station_core.StationCore.execute`), which runs the entry's action with the station's
rotor.  :func:`run_rotor_command` runs the same action with a given rotor port, for the web page's control
until it hands its requests to the core too.
"""

from __future__ import annotations

from nfwserver.commands.actions import NO_ROTOR, RotorControl, StationPort, Targets
from nfwserver.commands.parsing import Parsed

__all__ = ["NO_ROTOR", "RotorControl", "run_rotor_command"]


def run_rotor_command(parsed: Parsed, rotor: RotorControl | None, core: StationPort, source: str) -> str | None:
    """Run ``FLIP``/``PARK`` from ``source`` through the entry's action; None when done, else why not."""
    return parsed.command.action(Targets(core, rotor), parsed.value, source).refused
