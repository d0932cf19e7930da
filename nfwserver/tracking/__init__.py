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
