"""The station core: the one live state, the tracker that ticks it, and the command port.

Every output (DDE, dialects, TCP, EasyComm, PREDICT, rotor, radio, console) is an adapter on
:class:`StationCore`; see docs/ARCHITECTURE.md.
"""
