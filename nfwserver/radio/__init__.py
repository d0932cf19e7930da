"""Doppler tuning through Hamlib's rigctld (the channels it tunes are the core's:
:class:`nfwserver.channels.channel.Channel`).
"""

from nfwserver.lazy_exports import lazy_exports

_EXPORTS = {
    "DopplerTuner": "tuning",
    "RadioCoupling": "coupling",
    "RigctldBackend": "rigctld_backend",
    "RadioError": "backend",
    "RadioUnavailable": "backend",
    "DEFAULT_CHANNELS": "defaults",
}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
