"""Orbitron's DDE interface (service ``Orbitron``, topic ``Tracking``, items ``TrackingData``/``TrackingDataEx``).

Format, as Orbitron's driver clients (e.g. the MyDDE driver source and its documentation) parse it:
space-separated fields, each a two-letter label followed by its value; clients find fields by label.

    SN<name, blanks as _> AZ<az 0.0-360.0> EL<el, signed> DN<downlink Hz> UP<uplink Hz> DM<mode> UM<mode>

``DM``/``UM`` are optional; without a channel the frequencies are 0.  Example:
``SNISS_ZARYA AZ182.1 EL36.3 DN145800000 UP145800000 UMFM-N``.  An empty string means no satellite.
WXtrack publishes the same format (see :mod:`nfwserver.dialects.wxtrack`).
"""

from __future__ import annotations

import re

from nfwserver.dialects.base import Dialect, DialectView


def orbitron_name(name: str) -> str:
    """Orbitron's SN value: blanks become ``_``, brackets and quotes dropped."""
    text = re.sub(r"[()\[\]\"]", "", name.strip())
    return re.sub(r"\s+", "_", text) or "SAT"


def format_orbitron(view: DialectView | None) -> str:
    if view is None:
        return ""
    az = view.azimuth_deg % 360.0
    fields = [f"SN{orbitron_name(view.name or view.dde_name)}", f"AZ{az:.1f}", f"EL{view.elevation_deg:.1f}",
              f"DN{view.downlink_hz or 0}", f"UP{view.uplink_hz or view.downlink_hz or 0}"]
    if view.downlink_mode:
        fields.append(f"DM{view.downlink_mode}")
    if view.uplink_mode:
        fields.append(f"UM{view.uplink_mode}")
    return " ".join(fields).replace("EL-0.0", "EL0.0")


ORBITRON = Dialect("orbitron", "Orbitron", "Tracking", ("TrackingData", "TrackingDataEx"), format_orbitron)
