"""The running station assembled from a configuration: core, adapters, element loading, session state.
"""

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
