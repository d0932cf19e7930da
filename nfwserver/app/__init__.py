"""The running station assembled from a configuration: core, adapters, element loading, session state.
"""

from typing import TYPE_CHECKING

from nfwserver.lazy_exports import lazy_exports

_EXPORTS = {
    "Station": "station",
    "load_station_catalog": "station_catalog",
    "ElementStore": "element_store",
    "StateFile": "session_state",
    "SessionState": "session_state",
    "ConfigWatcher": "config_watcher",
    "ElementRefresher": "element_refresher",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)

if TYPE_CHECKING:  # the names as type checkers see them; at run time each module loads on first use
    from nfwserver.app.config_watcher import ConfigWatcher as ConfigWatcher
    from nfwserver.app.element_refresher import ElementRefresher as ElementRefresher
    from nfwserver.app.element_store import ElementStore as ElementStore
    from nfwserver.app.session_state import SessionState as SessionState
    from nfwserver.app.session_state import StateFile as StateFile
    from nfwserver.app.station import Station as Station
    from nfwserver.app.station_catalog import load_station_catalog as load_station_catalog
