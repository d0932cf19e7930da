"""Physical and time constants, each written once for the whole code base.

Units: kilometres, seconds, days.  Every other module imports from here; a second literal copy
of any of these values is a bug (the acceptance check greps for them).
"""

from __future__ import annotations

import math

#: Speed of light in vacuum (km/s), exact by definition of the metre.
SPEED_OF_LIGHT_KM_S = 299_792.458

#: WGS84 ellipsoid: equatorial radius (km), flattening, first eccentricity squared.  Observers and
#: sub-satellite points live on it.
WGS84_A_KM = 6378.137
WGS84_F = 1.0 / 298.257223563
WGS84_E2 = WGS84_F * (2.0 - WGS84_F)

#: WGS72 constants that SGP4 element sets are defined with: equatorial radius (km) and
#: gravitational parameter (km^3/s^2).
WGS72_A_KM = 6378.135
WGS72_MU_KM3_S2 = 398_600.8

#: Earth radius (km) of the Astronomical Almanac's low-precision Moon formulae (parallax -> distance).
ALMANAC_EARTH_RADIUS_KM = 6378.14
#: Earth radius (km) PREDICT 2.2 uses for its footprint, kept so its replies stay byte-identical.
PREDICT_EARTH_RADIUS_KM = 6378.16
#: PREDICT's footprint diameter factor (km): ``12756.33 * acos(R / (R + h))``.
PREDICT_FOOTPRINT_FACTOR_KM = 12756.33

#: Astronomical unit (km), IAU 2012.
AU_KM = 149_597_870.7

SECONDS_PER_DAY = 86_400.0
MINUTES_PER_DAY = 1_440.0
DAYS_PER_JULIAN_CENTURY = 36_525.0
#: Julian date of the J2000.0 epoch (2000-01-01T12:00 TT; used here on the UT/UTC scales as usual).
JD_J2000 = 2_451_545.0
#: Earth rotations per UT1 day relative to the mean equinox (IAU 1982 GMST rate at J2000).
SIDEREAL_TURNS_PER_UT1_DAY = 1.00273790935
#: The Earth's rotation rate (rad/s) relative to the mean equinox: 7.2921e-5.
EARTH_ROTATION_RAD_S = 2.0 * math.pi * SIDEREAL_TURNS_PER_UT1_DAY / SECONDS_PER_DAY
