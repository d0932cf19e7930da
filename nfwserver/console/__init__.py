"""The diagnostic console (Textual): live state, outgoing (F1) and incoming (F3) strings, pokes."""

from typing import TYPE_CHECKING  # noqa: E402

from nfwserver.lazy_exports import lazy_exports  # noqa: E402

_EXPORTS = {
    "NfwConsole": "app",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)

if TYPE_CHECKING:  # the names as type checkers see them; at run time each module loads on first use
    from nfwserver.console.app import NfwConsole as NfwConsole
