"""Doppler tuning through Hamlib's rigctld (the channels it tunes are the core's:
:class:`nfwserver.channels.channel.Channel`).
"""

from typing import TYPE_CHECKING

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

if TYPE_CHECKING:  # the names as type checkers see them; at run time each module loads on first use
    from nfwserver.radio.backend import RadioError as RadioError
    from nfwserver.radio.backend import RadioUnavailable as RadioUnavailable
    from nfwserver.radio.coupling import RadioCoupling as RadioCoupling
    from nfwserver.radio.defaults import DEFAULT_CHANNELS as DEFAULT_CHANNELS
    from nfwserver.radio.rigctld_backend import RigctldBackend as RigctldBackend
    from nfwserver.radio.tuning import DopplerTuner as DopplerTuner
