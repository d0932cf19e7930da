"""Orbitron's DDE interface: service ``Orbitron``, topic ``Tracking``, items ``TrackingData`` and ``TrackingDataEx``.

Fields are a two-letter label followed at once by the value; clients find them by label (a public
.NET client takes each value with ``IndexOf(label)`` up to the next blank, so every field it reads must
be followed by a blank; a Python one splits by position).  Decimal point always ``.``.

``TrackingData``::

    SN<name, blanks as _> AZ<az> EL<el> DN<downlink Hz> UP<uplink Hz> [DM<mode>] [UM<mode>]

e.g. ``SNISS_ZARYA AZ182.1 EL36.3 DN145800000 UP145800000 DMFM UMFM``; empty when nothing is tracked.

``TrackingDataEx`` is its own format, every field followed by a blank (so the string ends in one)::

    SN"<name, blanks kept>" AZ<az> EL<el> DN<Hz> UP<Hz> DM<mode> UM<mode> RA<range km> RR<range rate km/s>
    LO<sub-satellite longitude> LA<latitude> AL<altitude km> TU<UTC> TL<local time>

When nothing is in view it is only ``AOS"<name>"`` for the satellite to come; empty when there is no
satellite or no position (the .NET client ignores lines starting with ``A`` but indexes an empty
reply's first character, so an idle station that has a satellite selected sends the ``AOS`` form).

Our reading where Orbitron's own description is silent (recorded in docs/COMPATIBILITY.md):

- Names: brackets and quotes are dropped, control characters become blanks; ``ISS (ZARYA)`` is ``ISS_ZARYA`` in
  ``TrackingData`` and ``"ISS ZARYA"`` in ``TrackingDataEx``.
- ``UP0`` when the channel has no uplink (never the downlink frequency, which would key a transmitter
  on the downlink); ``DN0 UP0`` and no modes without a channel.  ``DM``/``UM`` are left out of
  ``TrackingData`` without a mode and written empty in ``TrackingDataEx``.
- Numbers: AZ/EL one decimal (azimuth 0.0..359.9), RA one decimal km, RR three decimals km/s,
  LO (east-positive, -180..180) and LA two decimals, AL one decimal km.
- TU/TL: ``YYYYMMDDhhmmss`` (no blank inside, sortable, whole seconds), UTC and the station's local time.
- Below the horizon (a position, but nothing in view): ``TrackingData`` still carries the values (rotor
  drivers decide about parking themselves); ``TrackingDataEx`` gives the ``AOS`` form.

WXtrack publishes the ``TrackingData`` format (see :mod:`nfwserver.dialects.wxtrack`).
"""

from __future__ import annotations

import re
from datetime import datetime

from nfwserver.dialects.base import Dialect, DialectView

_DROPPED = re.compile(r"[()\[\]\"]")
_CONTROL = re.compile(r"[\x00-\x1f\x7f]")


def _clean(name: str) -> str:
    """Brackets and quotes dropped, control characters made blanks, runs of blanks one, ends trimmed."""
    return re.sub(r"\s+", " ", _CONTROL.sub(" ", _DROPPED.sub("", name))).strip()


def _azimuth(az: float) -> str:
    return f"{round(az % 360.0, 1) % 360.0:.1f}"


def _signed(value: float, decimals: int) -> str:
    text = f"{value:.{decimals}f}"
    return text[1:] if text.startswith("-") and float(text) == 0.0 else text


def orbitron_name(name: str) -> str:
    """``TrackingData``'s SN value: blanks become ``_``, brackets, quotes and control characters dropped."""
    return _clean(name).replace(" ", "_") or "SAT"


def orbitron_quoted_name(name: str) -> str:
    """``TrackingDataEx``'s SN value: the name in quotes, blanks kept (runs of them made one)."""
    return '"' + (_clean(name) or "SAT") + '"'


def _stamp(when: datetime | None) -> str:
    return when.strftime("%Y%m%d%H%M%S") if when is not None else ""


def format_tracking_data(view: DialectView | None) -> str:
    """The ``TrackingData`` string (module docstring)."""
    if view is None:
        return ""
    fields = [f"SN{orbitron_name(view.name or view.dde_name)}", f"AZ{_azimuth(view.azimuth_deg)}",
              f"EL{_signed(view.elevation_deg, 1)}", f"DN{view.downlink_hz or 0}", f"UP{view.uplink_hz or 0}"]
    if view.downlink_mode:
        fields.append(f"DM{view.downlink_mode}")
    if view.uplink_mode:
        fields.append(f"UM{view.uplink_mode}")
    return " ".join(fields)


def format_tracking_data_ex(view: DialectView | None) -> str:
    """The ``TrackingDataEx`` string (module docstring)."""
    if view is None:
        return ""
    name = orbitron_quoted_name(view.name or view.dde_name)
    if not view.above_horizon:
        return f"AOS{name}"
    lat, lon, alt = view.subpoint if view.subpoint is not None else (0.0, 0.0, 0.0)
    fields = [f"SN{name}", f"AZ{_azimuth(view.azimuth_deg)}", f"EL{_signed(view.elevation_deg, 1)}",
              f"DN{view.downlink_hz or 0}", f"UP{view.uplink_hz or 0}", f"DM{view.downlink_mode or ''}",
              f"UM{view.uplink_mode or ''}", f"RA{(view.range_km or 0.0):.1f}",
              f"RR{_signed(view.range_rate_km_s, 3)}", f"LO{_signed(lon, 2)}", f"LA{_signed(lat, 2)}",
              f"AL{alt:.1f}", f"TU{_stamp(view.time)}", f"TL{_stamp(view.local_time)}"]
    return "".join(field + " " for field in fields)


ORBITRON = Dialect("orbitron", "Orbitron", "Tracking", ("TrackingData", "TrackingDataEx"), format_tracking_data,
                   (("TrackingDataEx", format_tracking_data_ex),))
#: The former name of :func:`format_tracking_data`.
format_orbitron = format_tracking_data
