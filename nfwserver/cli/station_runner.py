"""Keeping a started station running: headless (a service) or under the console, and from one to the other.

- :func:`start_report` is what ``run`` logs at start: observer, satellite and the enabled outputs.
- :func:`status_line` is the one-line status logged every :data:`STATUS_INTERVAL_S` of the station
  clock while headless.
- :func:`serve_headless` waits on the station clock until a signal sets ``stop`` or ``duration``
  seconds of that clock have passed, logging the status line on schedule.
- :func:`run_console` runs the Textual console and returns the exception that stopped it, if one
  did: ``run`` then carries on headless (a console failure never stops the station's outputs).
"""

from __future__ import annotations

import logging
import threading
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from nfwserver.app.station import Station
    from nfwserver.console.app import NfwConsole

log = logging.getLogger("nfwserver")

#: Seconds of station-clock time between headless status lines (ten minutes).
STATUS_INTERVAL_S = 600.0


def _satellite(station: Station) -> str:
    sat = station.core.state.selected()
    return f"{sat.dde_name} ({sat.catalog_number})" if sat is not None else "none selected"


def enabled_outputs(station: Station) -> list[str]:
    """One phrase per output the station serves."""
    cfg = station.config
    srv = cfg.server
    outputs = [f"Nova DDE (services {', '.join(srv.services)}; topic {srv.topic}; items {', '.join(srv.items)})"]
    outputs.extend(f"{d.dialect.name} DDE" for d in station.dialect_servers)
    if station.predict is not None:
        outputs.append(f"PREDICT UDP {cfg.dialects.predict_host}:{cfg.dialects.predict_port}")
    if station.tcp is not None:
        outputs.append(f"TCP {cfg.tcp.host}:{cfg.tcp.port}")
    if station.easycomm is not None:
        outputs.append(f"EasyComm {cfg.easycomm.device}")
    web = station.web
    if web is not None and web.address is not None:
        outputs.append(f"web dashboard {web.url} (control {'on' if web.control.enabled else 'off'})")
    if station.rotor is not None:
        where = f" {cfg.rotor.host}:{cfg.rotor.port}" if cfg.rotor.backend == "rotctld" else ""
        outputs.append(f"rotor ({cfg.rotor.backend}{where})")
    if station.radio is not None:
        outputs.append(f"radio ({cfg.radio.backend} {cfg.radio.host}:{cfg.radio.port})")
    return outputs


def start_report(station: Station) -> list[str]:
    """Observer, satellite and enabled outputs, one line each."""
    state = station.core.state
    observer = state.observer
    where = "configured" if station.config.observer_configured else "not configured: the built-in default"
    return [f"observer {observer} ({where})", f"satellite {_satellite(station)}",
            "outputs: " + ", ".join(enabled_outputs(station))]


def status_line(station: Station) -> str:
    """``status: ISS (25544) AZ 123.4 EL 12.3 AH Y; TUNE ON TRACK OFF; DDE clients 2 (1 advise); ...``."""
    snap = station.core.snapshot()
    sample = snap.last_sample
    if sample is not None and sample.look_angles is not None:
        la = sample.look_angles
        where = f"AZ {la.azimuth_deg:.1f} EL {la.elevation_deg:.1f} AH {'Y' if sample.above_horizon else 'N'}"
    else:
        where = "no position"
    conversations, loops = station.nova.client_count()
    parts = [f"status: {_satellite(station)} {where}",
             f"TUNE {'ON' if snap.state.feed_on else 'OFF'} TRACK {'ON' if snap.state.tracking else 'OFF'}",
             f"DDE clients {conversations} ({loops} advise)"]
    if station.tcp is not None:
        parts.append(f"TCP clients {station.tcp.client_count()}")
    parts.append(f"status word 0x{snap.status:04X}")
    return "; ".join(parts)


def serve_headless(station: Station, stop: threading.Event, duration_s: float | None,
                   interval_s: float = STATUS_INTERVAL_S) -> None:
    """Wait on the station clock until ``stop`` is set or ``duration_s`` passed; status every ``interval_s``."""
    clock = station.clock
    start = clock.monotonic()
    next_status = start + interval_s
    while not stop.is_set():
        now = clock.monotonic()
        if duration_s is not None and now - start >= duration_s:
            return
        if now >= next_status:
            log.info("%s", status_line(station))
            next_status += interval_s
            continue
        wait = next_status - now
        if duration_s is not None:
            wait = min(wait, start + duration_s - now)
        clock.wait(stop, wait)


def run_console(app: NfwConsole, **run_options: Any) -> BaseException | None:
    """Run ``app`` (a :class:`~nfwserver.console.app.NfwConsole`); the exception that stopped it, or None."""
    try:
        app.run(**run_options)
    except Exception as exc:  # the terminal driver itself failed
        return exc
    return app.failure
