"""The rotor layer: the Kansas City Tracker driver model, FlipAnts flip planning, backends, autotracking.
"""

from typing import TYPE_CHECKING

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

if TYPE_CHECKING:  # the names as type checkers see them; at run time each module loads on first use
    from nfwserver.rotor.backend import RotorError as RotorError
    from nfwserver.rotor.backend import RotorUnavailable as RotorUnavailable
    from nfwserver.rotor.coupling import RotorCoupling as RotorCoupling
    from nfwserver.rotor.geometry import RotorGeometry as RotorGeometry
    from nfwserver.rotor.kct_driver import KctDriver as KctDriver
    from nfwserver.rotor.rotctld_backend import RotctldBackend as RotctldBackend
    from nfwserver.rotor.sim_backend import SimulatedRotor as SimulatedRotor
    from nfwserver.rotor.tracks import SatelliteTracks as SatelliteTracks
