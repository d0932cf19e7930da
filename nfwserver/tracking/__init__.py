"""Tracking engine: pure computation (numpy), no I/O beyond reading element text.

Modules: ``elements`` (loading TLE, AMSAT verbose and OMM sets), ``catalog`` (satellites by catalog
number, update semantics, DDE names), ``observer`` and ``maidenhead`` (station position),
``horizon`` (minimum elevation by azimuth), ``timescale`` (UTC/UT1 to Julian dates), ``look_angles``
(azimuth, elevation, range, range rate from SGP4, scalar and vectorised), ``passes`` (AOS/TCA/LOS),
``doppler`` and ``derived`` (InstantTrack's realtime values).
"""

from nfwserver.blas_threads import single_threaded_blas

single_threaded_blas()  # before numpy loads (nfwserver.blas_threads)

from nfwserver.tracking.sgp4_selfcheck import ensure_working_sgp4  # noqa: E402

SGP4_CHOICE = ensure_working_sgp4()  # before any tracking module imports sgp4's classes

from typing import TYPE_CHECKING  # noqa: E402

from nfwserver.lazy_exports import lazy_exports  # noqa: E402

_EXPORTS = {
    "Catalog": "catalog",
    "Satellite": "catalog",
    "ElementSet": "elements",
    "load_elements": "elements",
    "load_element_file": "elements",
    "Observer": "observer",
    "parse_observer": "observer",
    "HorizonTable": "horizon",
    "LookAngleCalculator": "look_angles",
    "LookAngles": "look_angles",
    "find_passes": "passes",
    "Pass": "passes",
    "doppler_shift_hz": "doppler",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)

if TYPE_CHECKING:  # the names as type checkers see them; at run time each module loads on first use
    from nfwserver.tracking.catalog import Catalog as Catalog
    from nfwserver.tracking.catalog import Satellite as Satellite
    from nfwserver.tracking.doppler import doppler_shift_hz as doppler_shift_hz
    from nfwserver.tracking.elements import (
        ElementSet as ElementSet,
    )
    from nfwserver.tracking.elements import (
        load_element_file as load_element_file,
    )
    from nfwserver.tracking.elements import (
        load_elements as load_elements,
    )
    from nfwserver.tracking.horizon import HorizonTable as HorizonTable
    from nfwserver.tracking.look_angles import LookAngleCalculator as LookAngleCalculator
    from nfwserver.tracking.look_angles import LookAngles as LookAngles
    from nfwserver.tracking.observer import Observer as Observer
    from nfwserver.tracking.observer import parse_observer as parse_observer
    from nfwserver.tracking.passes import Pass as Pass
    from nfwserver.tracking.passes import find_passes as find_passes
