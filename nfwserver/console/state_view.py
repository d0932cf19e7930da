"""The console's state pane, line by line, as literal text.

Every function returns :class:`rich.text.Text` built by appending plain strings, so a satellite
name such as ``[bold red]PWNED[/]`` is shown exactly as typed and can never be read as markup.
Lines that read devices (rotor, radio, the TCP server, EasyComm) are built by :func:`guarded`: a
device that reports garbage (a rotctld answering ``nan``) makes its line say so instead of stopping
the console.  No line wraps: given the pane's width, the parts that can be long (a satellite's or a
channel's name) are shortened first, the antenna and the radio share a line only when they fit, and
:func:`fit` cuts whatever is still too long with an ellipsis (a device's error text in full is in the log
and in STATUS).

Units: angles in degrees, range in km, range rate in km/s, frequencies in MHz on screen, Doppler in
Hz, path loss in dB; times in the zone the :class:`~nfwserver.console.time_display.TimeDisplay` shows.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from datetime import datetime

from rich.text import Text

from nfwserver.console.time_display import TimeDisplay
from nfwserver.core.faces import CountsClients, WritesLines
from nfwserver.core.station_core import CoreSnapshot, StationCore
from nfwserver.core.status import describe
from nfwserver.radio.coupling import RadioCoupling
from nfwserver.rotor.coupling import RotorCoupling
from nfwserver.tracking.derived import RealtimeValues, realtime_values
from nfwserver.tracking.look_angles import PropagationError

log = logging.getLogger(__name__)


def guarded(label: str, build: Callable[[], Text | None]) -> Text | None:
    """``build()``, or one line saying why ``label`` cannot be shown (logged at debug level)."""
    try:
        return build()
    except Exception as exc:  # a device reporting garbage must not stop the console
        log.debug("console: %s line failed", label, exc_info=True)
        return Text(f"{label}: cannot show ({type(exc).__name__}: {exc})", style="red")


def fit(line: Text, width: int) -> Text:
    """``line`` cut to ``width`` characters with an ellipsis when longer (``width`` <= 0: as it is)."""
    if 0 < width < line.cell_len:
        line = line.copy()
        line.truncate(width, overflow="ellipsis")
    return line


def _shortened(text: str, room: int) -> str:
    """``text`` in at most ``room`` characters (at least 4), its end replaced by an ellipsis when cut."""
    room = max(room, 4)
    return text if len(text) <= room else text[:room - 1] + "\u2026"


def satellite_line(snap: CoreSnapshot, core: StationCore, clients: tuple[int, int], width: int = 0) -> Text:
    """``Satellite ISS (25544) ISS (ZARYA)  TUNE ON  TRACK OFF  clients 1 (1 advise)`` (DDE clients); the
    satellite's long name is shortened to keep the line within ``width`` (0: no limit)."""
    state = snap.state
    tail = (f"  TUNE {'ON' if state.feed_on else 'OFF'}  TRACK {'ON' if state.tracking else 'OFF'}"
            f"  clients {clients[0]} ({clients[1]} advise)")
    line = Text("Satellite ")
    sat = core.state.catalog.get(snap.catalog_number) if snap.catalog_number is not None else None
    if sat is None:
        line.append("none selected", style="yellow")
    else:
        line.append(sat.dde_name, style="bold")
        line.append(f" ({sat.catalog_number})")
        if sat.name != sat.dde_name:
            room = width - len(line) - 1 - len(tail) if width > 0 else len(sat.name)
            line.append(f" {_shortened(sat.name, room)}")
    line.append(tail)
    return line


def _latlon(lat: float, lon: float) -> str:
    return f"{abs(lat):.2f}{'N' if lat >= 0 else 'S'} {abs(lon):.2f}{'E' if lon >= 0 else 'W'}"


def realtime(core: StationCore, catalog_number: int | None, now: datetime,
             schedule: str | None = None) -> tuple[RealtimeValues | None, str]:
    """InstantTrack's realtime values for the satellite now, at its channel's downlink; or why not."""
    state = core.state
    sat = state.catalog.get(catalog_number) if catalog_number is not None else None
    if sat is None:
        return None, "no satellite selected"
    if state.observer is None:
        return None, "no observer: no position"
    channel = state.channels.get(sat.catalog_number)
    frequency = channel.satellite_downlink_hz() if channel is not None else None
    try:
        return realtime_values(sat.elements, state.observer, now, state.ut1_utc_s, frequency, schedule), ""
    except PropagationError as exc:
        return None, f"SGP4 cannot propagate {sat.catalog_number} now ({exc})"
    except ValueError as exc:  # a malformed mode schedule
        return None, f"mode schedule refused: {exc}"


def realtime_lines(values: RealtimeValues | None, why: str, core: StationCore, catalog_number: int | None,
                   above_horizon: bool | None, width: int = 0) -> list[Text]:
    """Position, sub-satellite point, orbit and the downlink's Doppler and path loss (the channel's name
    shortened to keep that line within ``width``; 0: no limit)."""
    if values is None:
        return [Text(why or "no position", style="yellow")]
    v = values
    up = above_horizon if above_horizon is not None else v.elevation_deg > 0
    style = "bold green" if up else ""
    lines = [Text(f"AZ {v.azimuth_deg:6.1f}  EL {v.elevation_deg:5.1f}  range {v.range_km:8.1f} km  "
                  f"RR {v.range_rate_km_s:+.4f} km/s  AH {'Y' if up else 'N'}", style=style)]
    sp = v.subpoint
    mode = f"mode {v.mode}" if v.mode else "mode -"
    lines.append(Text(f"Sub-sat {_latlon(sp.latitude_deg, sp.longitude_deg)} {sp.locator} {sp.height_km:.0f} km"
                      f"  orbit {v.rev} phase {v.phase}  {mode}  "
                      f"{'sunlit' if v.sunlit else 'eclipsed'}"))
    channel = core.state.channels.get(catalog_number) if catalog_number is not None else None
    if channel is None or v.doppler_hz is None:
        lines.append(Text("Downlink: no channel for this satellite, so no Doppler or path loss ([satellites] "
                          "channels)", style="dim"))
    else:
        head = f"Downlink {channel.satellite_downlink_hz() / 1e6:.4f} MHz ("
        loss = "path loss -"  # below the horizon (AH N on the line above)
        if up and v.path_loss_db is not None:
            loss = f"path loss {v.path_loss_db:.1f} dB"
        tail = f") Doppler {v.doppler_hz:+,.0f} Hz  {loss}"
        name = channel.name if width <= 0 else _shortened(channel.name, width - len(head) - len(tail))
        line = Text(head)
        line.append(name)
        line.append(tail)
        lines.append(line)
    return lines


def _angle(value: float | None) -> str:
    if value is None:
        return "-"
    return f"{value:.1f}" if math.isfinite(value) else str(value)


def elements_line(core: StationCore, catalog_number: int | None, now: datetime, stale_days: float) -> Text | None:
    """``Elements 20 days old (over 14): positions drift; nfwserver elements update`` for the selected
    satellite when its element set is older than ``stale_days``; None otherwise."""
    sat = core.state.catalog.get(catalog_number) if catalog_number is not None else None
    if sat is None:
        return None
    age = sat.age_days(now)
    if age <= stale_days:
        return None
    return Text(f"Elements {age:.0f} days old (over {stale_days:g}): positions drift; nfwserver elements update",
                style="yellow")


def antenna_lines(snap: CoreSnapshot, radio: Text, width: int = 0) -> list[Text]:
    """``Antenna az/el (source)  Radio: ...`` on one line when it fits in ``width`` (0: no limit), else two."""
    ant = snap.state.antenna
    line = Text(f"Antenna {_angle(ant.azimuth_deg)}/{_angle(ant.elevation_deg)} ({ant.source or 'unknown'})")
    if not radio:
        return [line]
    if width > 0 and line.cell_len + 2 + radio.cell_len > width:
        return [line, radio]
    line.append("  ")
    line.append_text(radio)
    return [line]


def rotor_line(rotor: RotorCoupling) -> Text:
    """Target, read-back, flip mode and state, suspension, KCT status bits."""
    driver = rotor.driver
    pos = driver.rotor_position()
    actual = f"{_angle(pos[0])}/{_angle(pos[1])}" if pos is not None else "unreachable"
    _, _, tgt_el, tgt_az = driver.positions()
    target = f"{_angle(tgt_az)}/{_angle(tgt_el)}" if tgt_az is not None else "-"
    flip = f"flip {rotor.flip_mode} ({'inverted' if rotor.flip_state else 'normal'})"
    bits = driver.status().bits
    line = Text(f"Rotor: target {target}  actual {actual}  {flip}  KCT 0x{int(bits):02X}")
    return line


def radio_line(radio: RadioCoupling | None, doppler_on: bool) -> Text:
    state = "ON" if doppler_on else "OFF"
    if radio is None:
        return Text(f"Radio: none configured (tuning {state}; Ctrl+D explains)", style="dim")
    r = radio.current_result()
    if not radio.tuner.available:
        return Text(f"Radio: Doppler tuning {state}, radio unreachable ({radio.tuner.last_error})", style="red")
    if radio.without_channel():
        return Text(f"Radio: Doppler tuning {state}, idle: no radio channel for this satellite", style="yellow")
    if r is not None:
        tx = f" TX {r.tx_hz / 1e6:.6f} MHz" if r.tx_hz else ""
        return Text(f"Radio: Doppler tuning {state}, RX {r.rx_hz / 1e6:.6f} MHz{tx}")
    return Text(f"Radio: Doppler tuning {state}")


def outputs_line(tcp: CountsClients | None, easycomm: WritesLines | None) -> Text | None:
    """TCP clients and the last EasyComm line, when those outputs exist."""
    parts = Text()
    if tcp is not None:
        parts.append(f"TCP clients {tcp.client_count()}")
    if easycomm is not None:
        if parts:
            parts.append("  ")
        parts.append("EasyComm ")
        parts.append(easycomm.last_line or "-")
    return parts if parts else None


def status_line(snap: CoreSnapshot, times: TimeDisplay, now: datetime) -> Text:
    status = ", ".join(describe(snap.status)) or "ok"
    return Text(f"Status 0x{snap.status:04X}: {status}  {snap.state.rate_hz:g} Hz  {times.stamp(now)}")
