"""The one table of how a running station takes a changed configuration (see
:mod:`nfwserver.config.live_reload`): :meth:`~nfwserver.app.station.Station.apply_config` applies every live
part that changed to the station's core, in this order, and names the restart-only parts that changed.

Parts not listed are read from the configuration when used (favourites), used only at start (the start-up
satellite, ``tune``, ``track``, the state file, the console's mode schedules: they say how a station starts,
not how it runs) or describe the file itself.
"""

from __future__ import annotations

import logging

from nfwserver.config.live_reload import ConfigPart
from nfwserver.config.schema import Config
from nfwserver.core.station_core import StationCore

__all__ = ["CONFIG_PARTS"]

log = logging.getLogger(__name__)


def _configure_state(core: StationCore, new: Config) -> None:
    """The live state's observer, horizon, UT1-UTC, rate and channels, in one change."""
    core.state.configure(observer=new.observer, horizon=new.horizon, ut1_utc_s=new.server.ut1_utc_s,
                                 rate_hz=new.server.rate_hz, channels=new.channels)


def _set_dde_names(core: StationCore, new: Config) -> None:
    """The satellites' 12-character DDE names; a name the catalog refuses is logged and skipped."""
    for catnr, name in new.dde_names.items():
        try:
            core.state.catalog.set_dde_name(catnr, name)
        except ValueError as exc:
            log.warning("DDE name for %s not applied: %s", catnr, exc)
    core.state.catalog_changed()


def _set_doppler(core: StationCore, new: Config) -> None:
    """Doppler tuning switched on or off, as the console's Ctrl+D does."""
    core.set_doppler(new.radio.enabled, source="configuration")


def _web_server_follows(core: StationCore, new: Config) -> None:
    """Nothing in the core: :meth:`~nfwserver.app.station.Station.apply_config` hands the new ``[web]``
    control, token and host names to its web server, which reads them at the next request."""


#: Every part a reload may change: live ones with how they are applied, restart-only ones without.
CONFIG_PARTS: tuple[ConfigPart[StationCore], ...] = (
    ConfigPart("[observer], [horizon], [server] ut1_utc_s and rate_hz, [satellites] channels",
               ("observer", "horizon", "server.ut1_utc_s", "server.rate_hz", "channels"), _configure_state),
    ConfigPart("[satellites] names", ("dde_names",), _set_dde_names),
    ConfigPart("[radio] enabled", ("radio.enabled",), _set_doppler),
    ConfigPart("[elements]", ("elements",)),
    ConfigPart("[rotor]", ("rotor",)),
    ConfigPart("[radio] backend", ("radio.backend", "radio.host", "radio.port")),
    ConfigPart("[radio] step_hz and knob_tolerance_hz", ("radio.step_hz", "radio.knob_tolerance_hz")),
    ConfigPart("[server] services/topic/items", ("server.services", "server.topic", "server.items")),
    ConfigPart("[dialects]", ("dialects",)),
    ConfigPart("[tcp]", ("tcp",)),
    ConfigPart("[easycomm]", ("easycomm",)),
    ConfigPart("[web] control, token and hostnames", ("web.control", "web.token", "web.hostnames"),
               _web_server_follows),
    ConfigPart("[web] enabled, host, port and allow", ("web.enabled", "web.host", "web.port", "web.allow")),
)
