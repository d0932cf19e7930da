"""The Nova for Windows DDE string and poke grammar.

Outgoing string (one per publish tick, after ``TUNE ON``)::

    SatName AZ:<az> EL:<el> RR:<rr> AH:<Y|N>

- ``SatName``: at most 12 characters, no spaces (clients take the first word as the name).
- ``AZ``: degrees, one decimal, unsigned, 0.0-359.9 (a value that rounds to 360.0 prints 0.0).
- ``EL``: degrees, one decimal, signed only when negative; never ``-0.0``.
- ``RR``: range rate in km/s, positive receding, ten decimals; never ``-0.0000000000``.
- ``AH``: ``Y`` when the elevation is above the horizon table at that azimuth, else ``N``.

Incoming pokes (any item of the topic): ``TUNE ON``, ``TUNE OFF``, ``TRACK ON``, ``TRACK OFF``,
``SAT=<catalog number>``, ``ANTAZ=<deg>``, ``ANTEL=<deg>``: their grammar is the command table's
(:mod:`nfwserver.commands`).
"""

from __future__ import annotations

__all__ = ["MAX_NAME_LENGTH", "format_azimuth", "format_elevation", "format_nova", "format_range_rate"]

MAX_NAME_LENGTH = 12


def format_azimuth(az_deg: float) -> str:
    """``AZ`` field: one decimal in 0.0..359.9."""
    text = f"{az_deg % 360.0:.1f}"
    return "0.0" if text == "360.0" else text


def format_elevation(el_deg: float) -> str:
    """``EL`` field: one decimal, signed when negative, never ``-0.0``."""
    text = f"{el_deg:.1f}"
    return "0.0" if text == "-0.0" else text


def format_range_rate(rr_km_s: float) -> str:
    """``RR`` field: km/s with ten decimals, never negative zero."""
    text = f"{rr_km_s:.10f}"
    return text[1:] if text.startswith("-") and not text.strip("-0.") else text


def format_nova(name: str, az_deg: float, el_deg: float, rr_km_s: float, above_horizon: bool) -> str:
    """The whole Nova string; ``name`` is cleaned to at most 12 characters without blanks."""
    clean = "".join(ch for ch in name if ch.isprintable() and not ch.isspace())[:MAX_NAME_LENGTH] or "SAT"
    return (
        f"{clean} AZ:{format_azimuth(az_deg)} EL:{format_elevation(el_deg)} "
        f"RR:{format_range_rate(rr_km_s)} AH:{'Y' if above_horizon else 'N'}"
    )
