"""The station core: the one live state, the tracker that ticks it, and the command port.

Every output (DDE, dialects, TCP, EasyComm, PREDICT, rotor, radio, console) is an adapter on
:class:`StationCore`; see docs/ARCHITECTURE.md.
"""

from nfwserver.core.events import Direction, Event, EventLog
from nfwserver.core.publisher import Publisher, PublishStats, run_virtual
from nfwserver.core.sample import AntennaPosition, TickSample
from nfwserver.core.state import StateSnapshot, StationState
from nfwserver.core.station_core import CommandResult, CoreSnapshot, StationCore
from nfwserver.core.status import INTERFACE_VERSION, ArithmeticErrorCode, StatusBit
from nfwserver.core.tick_worker import TickWorker
from nfwserver.core.tracker import Tracker

__all__ = [
    "INTERFACE_VERSION",
    "AntennaPosition",
    "ArithmeticErrorCode",
    "CommandResult",
    "CoreSnapshot",
    "Direction",
    "Event",
    "EventLog",
    "PublishStats",
    "Publisher",
    "StateSnapshot",
    "StationCore",
    "StationState",
    "StatusBit",
    "TickSample",
    "TickWorker",
    "Tracker",
    "run_virtual",
]
