"""The station core: the one live state, the tracker that ticks it, and the command port.

Every output (DDE, dialects, TCP, EasyComm, PREDICT, rotor, radio, console) is an adapter on
:class:`StationCore`; see docs/ARCHITECTURE.md.
"""

from typing import TYPE_CHECKING

from nfwserver.lazy_exports import lazy_exports

_EXPORTS = {
    "Direction": "events",
    "Event": "events",
    "EventLog": "events",
    "PublishStats": "publisher",
    "Publisher": "publisher",
    "run_virtual": "publisher",
    "AntennaPosition": "sample",
    "TickSample": "sample",
    "StateSnapshot": "state",
    "StationState": "state",
    "CommandResult": "station_core",
    "CoreSnapshot": "station_core",
    "StationCore": "station_core",
    "INTERFACE_VERSION": "status",
    "ArithmeticErrorCode": "status",
    "StatusBit": "status",
    "TickWorker": "tick_worker",
    "Tracker": "tracker",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)

if TYPE_CHECKING:  # the names as type checkers see them; at run time each module loads on first use
    from nfwserver.core.events import Direction as Direction
    from nfwserver.core.events import Event as Event
    from nfwserver.core.events import EventLog as EventLog
    from nfwserver.core.publisher import (
        Publisher as Publisher,
    )
    from nfwserver.core.publisher import (
        PublishStats as PublishStats,
    )
    from nfwserver.core.publisher import (
        run_virtual as run_virtual,
    )
    from nfwserver.core.sample import AntennaPosition as AntennaPosition
    from nfwserver.core.sample import TickSample as TickSample
    from nfwserver.core.state import StateSnapshot as StateSnapshot
    from nfwserver.core.state import StationState as StationState
    from nfwserver.core.station_core import (
        CommandResult as CommandResult,
    )
    from nfwserver.core.station_core import (
        CoreSnapshot as CoreSnapshot,
    )
    from nfwserver.core.station_core import (
        StationCore as StationCore,
    )
    from nfwserver.core.status import (
        INTERFACE_VERSION as INTERFACE_VERSION,
    )
    from nfwserver.core.status import (
        ArithmeticErrorCode as ArithmeticErrorCode,
    )
    from nfwserver.core.status import (
        StatusBit as StatusBit,
    )
    from nfwserver.core.tick_worker import TickWorker as TickWorker
    from nfwserver.core.tracker import Tracker as Tracker
