"""Hamlib's daemons (rotctld, rigctld) over TCP: the line client and the command table.
"""

from nfwserver.lazy_exports import lazy_exports

_EXPORTS = {
    "HamlibConnection": "connection",
    "HamlibError": "connection",
    "HamlibUnavailable": "connection",
    "HamlibCommand": "commands",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
