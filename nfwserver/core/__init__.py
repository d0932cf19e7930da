"""The station core: the one live state, the tracker that ticks it, and the command port.

Every output (DDE, dialects, TCP, EasyComm, PREDICT, rotor, radio, console) is an adapter on
:class:`StationCore`; see docs/ARCHITECTURE.md.
"""

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
