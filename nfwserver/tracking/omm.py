"""CCSDS Orbit Mean-elements Messages (OMM) in CelesTrak's JSON and CSV forms.

Both forms carry the same keys (``OBJECT_NAME``, ``OBJECT_ID``, ``EPOCH``, ``MEAN_MOTION``,
``ECCENTRICITY``, ``INCLINATION``, ``RA_OF_ASC_NODE``, ``ARG_OF_PERICENTER``, ``MEAN_ANOMALY``,
``EPHEMERIS_TYPE``, ``CLASSIFICATION_TYPE``, ``NORAD_CAT_ID``, ``ELEMENT_SET_NO``,
``REV_AT_EPOCH``, ``BSTAR``, ``MEAN_MOTION_DOT``, ``MEAN_MOTION_DDOT``), in the units of the TLE
(degrees, rev/day, rev/day^2 for the first derivative divided by two).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from datetime import datetime, timezone
from typing import Any

from nfwserver.tracking.tle import TleError, TleFields, check_ranges


def _epoch(text: str) -> datetime:
    text = str(text).strip().rstrip("Z")
    try:
        when = datetime.fromisoformat(text)
    except ValueError:
        raise TleError(f"OMM EPOCH {text!r} is not an ISO-8601 time") from None
    return when.replace(tzinfo=timezone.utc) if when.tzinfo is None else when.astimezone(timezone.utc)


def _designator(object_id: str) -> str:
    """``1998-067A`` -> ``98067A``; characters a designator cannot hold (not A-Z, 0-9, -) are dropped."""
    text = re.sub(r"[^0-9A-Z-]", "", str(object_id or "").strip().upper())
    if len(text) >= 9 and text[4] == "-":
        return text[2:4] + text[5:]
    return text[:8]


def _classification(value: object) -> str:
    """U, C or S; anything else (which a TLE line could not hold) is taken as U."""
    text = str(value)[:1].upper()
    return text if text in ("U", "C", "S") else "U"


def omm_fields(record: Mapping[str, object]) -> tuple[str, TleFields]:
    """(name, values) of one OMM record; raises :class:`TleError` for a missing or bad value."""
    def get(key: str, default: object = None) -> Any:
        value = record.get(key, default)
        if value is None or value == "":
            if default is not None:
                return default
            raise TleError(f"OMM record lacks {key}")
        return value

    try:
        fields = TleFields(
            catalog_number=int(get("NORAD_CAT_ID")),
            classification=_classification(get("CLASSIFICATION_TYPE", "U")),
            international_designator=_designator(str(get("OBJECT_ID", ""))),
            epoch=_epoch(str(get("EPOCH"))),
            mean_motion_dot=float(get("MEAN_MOTION_DOT", 0.0)),
            mean_motion_ddot=float(get("MEAN_MOTION_DDOT", 0.0)),
            bstar=float(get("BSTAR", 0.0)),
            ephemeris_type=int(get("EPHEMERIS_TYPE", 0)),
            element_number=int(get("ELEMENT_SET_NO", 0)),
            inclination_deg=float(get("INCLINATION")),
            raan_deg=float(get("RA_OF_ASC_NODE")),
            eccentricity=float(get("ECCENTRICITY")),
            arg_perigee_deg=float(get("ARG_OF_PERICENTER")),
            mean_anomaly_deg=float(get("MEAN_ANOMALY")),
            mean_motion_rev_per_day=float(get("MEAN_MOTION")),
            rev_number=int(get("REV_AT_EPOCH", 0)),
        )
    except (TypeError, ValueError, OverflowError) as exc:
        if isinstance(exc, TleError):
            raise
        raise TleError(f"OMM record has an unreadable value ({exc})") from None
    check_ranges(fields)
    return str(record.get("OBJECT_NAME") or "").strip(), fields
