"""SatPC32's DDE interface (service ``SatPC32``, topic ``SatPcDdeConv``, item ``SatPcDdeItem``).

Fields in this order, a two-letter label followed by its value, single blanks, the line ending in
CR LF; clients parse by label, by position (``split(" ")``), or test for the ``**`` prefix:

    SN<name> AZ<az> EL<el> UP<uplink Hz> UM<mode> DN<downlink Hz> DM<mode> MA<mean anomaly, 256ths>

e.g. ``SNFO-29 AZ56.7 EL6.8 UP145951275 UMLSB DN435853062 DMUSB MA52.6`` + CR LF.  ``UM`` and ``DM``
may be empty (no mode known; the label stays so positions hold).  ``** NO SATELLITE **`` + CR LF
when nothing is tracked: no satellite, no position, or the satellite below the horizon table.

Our reading where the description is silent (recorded in docs/COMPATIBILITY.md): the name is the
short (DDE) name with blanks and control characters replaced by ``_`` so positional parsing holds;
``UP0``/``DN0`` without a channel or uplink; AZ/EL/MA one decimal, decimal point ``.``; the optional
``RR`` field is not sent (its unit is not documented, and clients that split by position read the
first eight fields).
"""

from __future__ import annotations

import re

from nfwserver.dialects.base import Dialect, DialectView

CRLF = "\r\n"
NO_SATELLITE = "** NO SATELLITE **"


def satpc32_name(name: str) -> str:
    return re.sub(r"[\s\x00-\x1f\x7f]+", "_", name.strip()) or "SAT"


def format_satpc32(view: DialectView | None) -> str:
    if view is None or not view.above_horizon:
        return NO_SATELLITE + CRLF
    az = round(view.azimuth_deg % 360.0, 1) % 360.0
    el = f"{view.elevation_deg:.1f}".replace("-0.0", "0.0")
    return (f"SN{satpc32_name(view.dde_name)} AZ{az:.1f} EL{el} UP{view.uplink_hz or 0} UM{view.uplink_mode or ''} "
            f"DN{view.downlink_hz or 0} DM{view.downlink_mode or ''} MA{(view.phase or 0.0):.1f}{CRLF}")


SATPC32 = Dialect("satpc32", "SatPC32", "SatPcDdeConv", ("SatPcDdeItem",), format_satpc32)
