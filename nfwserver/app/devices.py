"""Building the rotor and radio adapters from their configuration sections.

Construction only: no connection is opened until the coupling's worker starts (``start()``).
"""

from __future__ import annotations

from nfwserver.clock import Clock
from nfwserver.config.schema import RadioConfig, RotorConfig
from nfwserver.core.events import Direction
from nfwserver.core.station_core import StationCore
from nfwserver.health import Backoff, LinkHealth
from nfwserver.radio.coupling import RadioCoupling
from nfwserver.radio.rigctld_backend import RigctldBackend
from nfwserver.radio.tuning import DopplerTuner
from nfwserver.rotor.backend import RotorBackend
from nfwserver.rotor.coupling import RotorCoupling
from nfwserver.rotor.geometry import RotorGeometry
from nfwserver.rotor.kct_driver import KctDriver
from nfwserver.rotor.kct_rotor_link import STALL_BACKOFF
from nfwserver.rotor.rotctld_backend import RotctldBackend
from nfwserver.rotor.sim_backend import SimulatedRotor
from nfwserver.rotor.tracks import SatelliteTracks


def make_rotor(rc: RotorConfig, core: StationCore, clock: Clock) -> RotorCoupling | None:
    """The autotracking coupling for ``[rotor]`` (None when ``backend = "none"``)."""
    if rc.backend == "none":
        return None
    geometry = RotorGeometry.preset(rc.geometry)
    backend: RotorBackend
    if rc.backend == "sim":
        backend = SimulatedRotor(clock, geometry, rc.speed_deg_s, rc.speed_deg_s)
    else:
        backend = RotctldBackend(clock, geometry, rc.host, rc.port, health=_daemon_link(core, "rotctld"))
    driver = KctDriver(clock, backend, geometry, health=core.health.link("rotor", STALL_BACKOFF))
    driver.set_parking(rc.park_delay_minutes, rc.park_azimuth_deg, rc.park_elevation_deg)
    tracks = SatelliteTracks(core.state)
    return RotorCoupling(
        driver, tracks.predict, tracks.pass_track, rc.threshold_deg, rc.speed_deg_s, rc.max_lead_s,
        rc.after_los, rc.flip,
        on_position=lambda az, el: core.report_antenna_position(az, el, "rotor"),
        on_event=lambda text: _note(core, text),
    )


#: retry delays of a Hamlib daemon's link (seconds)
DAEMON_BACKOFF = Backoff(0.2, 0.4)


def _daemon_link(core: StationCore, name: str) -> LinkHealth:
    """The station's link for a Hamlib daemon: retried after 0.2 s, then every 0.4 s (a refused connect to a
    daemon costs nothing, so one that returns is found again within two ticks at 5 Hz)."""
    return core.health.link(name, DAEMON_BACKOFF)


def _note(core: StationCore, text: str) -> None:
    """A rotor event (announcement, stall, refused target) in the station's event stream."""
    core.events.add(core.clock.now(), Direction.INFO, "note", text, client="rotor")


def make_radio(rc: RadioConfig, core: StationCore, clock: Clock) -> RadioCoupling | None:
    """The Doppler-tuning coupling for ``[radio]`` (None without a backend or any channel)."""
    if rc.backend != "rigctld":
        return None
    first = next(iter(core.state.channels.values()), None)
    if first is None:
        return None
    backend = RigctldBackend(clock, rc.host, rc.port, health=_daemon_link(core, "rigctld"))
    tuner = DopplerTuner(first, backend, rc.step_hz, rc.knob_tolerance_hz, clock=clock)
    return RadioCoupling(tuner, core.state, clock)
