"""The "now tracking" part of a frame: what the station publishes this tick, as plain JSON values.

Everything is read from the one live state and the tick's :class:`~nfwserver.core.sample.TickSample`;
nothing is kept between frames.  Units: angles in degrees (azimuth from true north through east,
elevation above the geodetic horizontal), range in km, range rate in km/s (positive receding),
frequencies in Hz, times ISO-8601 UTC with ``Z``, ages in days.  ``docs/WEB.md`` lists the fields.
"""

from __future__ import annotations

import math
from datetime import datetime, timezone

from nfwserver.core.sample import TickSample
from nfwserver.core.station_core import StationCore
from nfwserver.core.status import describe
from nfwserver.tracking.derived import footprint_km, realtime_values
from nfwserver.tracking.look_angles import PropagationError

#: Elements older than this many days are shown with a staleness warning (LEO sets age in days).
STALE_AFTER_DAYS = 7.0


def iso(when: datetime | None) -> str | None:
    """ISO-8601 UTC with milliseconds and ``Z`` (None stays None)."""
    if when is None:
        return None
    return when.astimezone(timezone.utc).isoformat(timespec="milliseconds").replace("+00:00", "Z")


def _finite(value: float | None, digits: int) -> float | None:
    return round(value, digits) if value is not None and math.isfinite(value) else None


def satellite_part(core: StationCore, now: datetime) -> dict[str, object] | None:
    sat = core.state.snapshot().satellite
    if sat is None:
        return None
    age = sat.age_days(now)
    return {"catalog_number": sat.catalog_number, "name": sat.name, "dde_name": sat.dde_name,
            "epoch": iso(sat.elements.epoch), "age_days": round(age, 2), "stale": abs(age) > STALE_AFTER_DAYS}


def position_part(sample: TickSample | None) -> dict[str, object] | None:
    """Look angles of the tick (the values the Nova string was formatted from)."""
    if sample is None or sample.look_angles is None:
        return None
    la = sample.look_angles
    return {"az": _finite(la.azimuth_deg, 4), "el": _finite(la.elevation_deg, 4),
            "range_km": _finite(la.range_km, 3), "range_rate_km_s": _finite(la.range_rate_km_s, 10),
            "above_horizon": sample.above_horizon}


def realtime_part(core: StationCore,
                  sample: TickSample | None) -> tuple[dict[str, object] | None, dict[str, object] | None]:
    """(sub-satellite point and footprint, Doppler of the satellite's channel) for the tick's instant."""
    state = core.state.snapshot()
    sat = state.satellite
    if sample is None or sat is None or state.observer is None or sample.catalog_number != sat.catalog_number:
        return None, None
    channel = state.channels.get(sat.catalog_number)
    try:
        values = realtime_values(sat.elements, state.observer, sample.time, state.ut1_utc_s)
    except (PropagationError, ValueError):
        return None, None
    sp = values.subpoint
    sub = {"lat": round(sp.latitude_deg, 4), "lon": round(sp.longitude_deg, 4), "height_km": round(sp.height_km, 1),
           "locator": sp.locator, "footprint_km": round(footprint_km(sp.height_km), 1), "sunlit": values.sunlit}
    doppler = None
    if channel is not None and sample.look_angles is not None:
        rx, tx = channel.ground_frequencies(sample.look_angles.range_rate_km_s)
        uplink = channel.satellite_uplink_hz()
        doppler = {"channel": channel.name, "downlink_hz": round(channel.satellite_downlink_hz()),
                   "uplink_hz": None if uplink is None else round(uplink),
                   "rx_hz": round(rx), "tx_hz": None if tx is None else round(tx)}
    return sub, doppler


def status_part(sample: TickSample | None, core: StationCore) -> dict[str, object]:
    word = sample.status if sample is not None else core.tracker.status_word()
    return {"word": word, "hex": f"0x{word:04X}", "flags": describe(word),
            "error_code": int(sample.error) if sample is not None else 0,
            "interface_version": sample.interface_version if sample is not None else 1}


def now_tracking(core: StationCore, sample: TickSample | None, now: datetime) -> dict[str, object]:
    """The "now tracking" block: satellite, switches, Nova string, look angles, sub-point, Doppler, status."""
    state = core.state.snapshot()
    sub, doppler = realtime_part(core, sample)
    return {
        "time": iso(sample.time if sample is not None else now),
        "satellite": satellite_part(core, now),
        "tune": state.feed_on, "track": state.tracking, "radio_tuning": state.doppler_on,
        "nova": sample.text if sample is not None else "",
        "position": position_part(sample), "subpoint": sub, "doppler": doppler,
        "status": status_part(sample, core),
        "observer": None if state.observer is None else {
            "lat": state.observer.latitude_deg, "lon": state.observer.longitude_deg,
            "alt_m": state.observer.altitude_m},
    }
