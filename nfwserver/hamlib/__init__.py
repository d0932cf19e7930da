"""Hamlib's daemons (rotctld, rigctld) over TCP: the line client and the command table.
"""

from typing import TYPE_CHECKING

from nfwserver.lazy_exports import lazy_exports

_EXPORTS = {
    "HamlibConnection": "connection",
    "HamlibError": "connection",
    "HamlibUnavailable": "connection",
    "HamlibCommand": "commands",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)

if TYPE_CHECKING:  # the names as type checkers see them; at run time each module loads on first use
    from nfwserver.hamlib.commands import HamlibCommand as HamlibCommand
    from nfwserver.hamlib.connection import (
        HamlibConnection as HamlibConnection,
    )
    from nfwserver.hamlib.connection import (
        HamlibError as HamlibError,
    )
    from nfwserver.hamlib.connection import (
        HamlibUnavailable as HamlibUnavailable,
    )
