"""The rotor layer: the Kansas City Tracker driver model, FlipAnts flip planning, backends, autotracking.
"""

from nfwserver.lazy_exports import lazy_exports

_EXPORTS = {
    "KctDriver": "kct_driver",
    "RotorGeometry": "geometry",
    "RotorCoupling": "coupling",
    "SatelliteTracks": "tracks",
    "SimulatedRotor": "sim_backend",
    "RotctldBackend": "rotctld_backend",
    "RotorError": "backend",
    "RotorUnavailable": "backend",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
