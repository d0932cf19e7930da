"""SatPC32's DDE interface (service ``SatPC32``, topic ``SatPcDdeConv``, item ``SatPcDdeItem``).

Format (labels followed by values, single blanks; clients parse by label and some by order):

    SN<name> AZ<az> EL<el> UP<uplink Hz> UM<mode> DN<downlink Hz> DM<mode> MA<mean anomaly, 256ths>

e.g. ``SNFO-29 AZ56.7 EL6.8 UP145951275 UMLSB DN435853062 DMUSB MA52.6``.  SatPC32 publishes
``** NO SATELLITE **`` when no satellite is up; so does this dialect when there is no satellite, no
position, or the satellite is below the horizon table.
"""

from __future__ import annotations

from nfwserver.dialects.base import Dialect, DialectView

NO_SATELLITE = "** NO SATELLITE **"


def format_satpc32(view: DialectView | None) -> str:
    if view is None or not view.above_horizon:
        return NO_SATELLITE
    return (f"SN{view.dde_name} AZ{view.azimuth_deg % 360.0:.1f} EL{view.elevation_deg:.1f} "
            f"UP{view.uplink_hz or 0} UM{view.uplink_mode or view.downlink_mode or 'FM'} "
            f"DN{view.downlink_hz or 0} DM{view.downlink_mode or 'FM'} MA{(view.phase or 0.0):.1f}")


SATPC32 = Dialect("satpc32", "SatPC32", "SatPcDdeConv", ("SatPcDdeItem",), format_satpc32)
