"""The diagnostic console (Textual): live state, outgoing (F1) and incoming (F3) strings, pokes."""

from nfwserver.lazy_exports import lazy_exports  # noqa: E402

_EXPORTS = {
    "NfwConsole": "app",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
