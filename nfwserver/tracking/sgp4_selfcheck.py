"""Start-up check that ``sgp4`` computes right on this machine, with fallbacks when it does not.

Why: under Wine 8.0 the compiled extension of ``sgp4`` (2.27, win_amd64 wheel) parses TLE lines
into garbage — mean motion 0.0, B* NaN — so every propagation fails with "SGP4 error 2" and a
station would serve empty strings.  Its propagator is right when initialised with ``sgp4init``
from values parsed by ``sgp4``'s own pure-Python TLE reader; its pure-Python model is right too.

The check parses and propagates a reference element set and compares with published positions,
then keeps the first of these that agrees (within 1 m):

``compiled``
    ``sgp4.api.Satrec.twoline2rv`` as installed (normal on Linux and on real Windows).
``compiled-python-parser``
    The compiled propagator, initialised through ``sgp4init`` from the pure-Python TLE reader:
    ``sgp4.api.Satrec.twoline2rv`` is replaced by a classmethod doing that.  Full speed.
``python``
    ``sgp4``'s pure-Python model: ``sgp4.api.Satrec``/``SatrecArray`` become ``sgp4.model``'s
    (about a hundred times slower).  Modules must import those names after the switch, which
    is why :mod:`nfwserver.tracking` runs the check when the package is first imported.

The choice is a fact about the machine that its operator can do nothing about, so it is logged at INFO:
shown by a command under ``-v``, and written once into the station's log at each start
(:meth:`nfwserver.app.station.Station.start`), never as a warning before every command's output.

Reference: satellite 00005 from Vallado, Crawford, Hujsak and Kelso, "Revisiting Spacetrack
Report #3" (AIAA 2006-6753), its verification output ``tcppver.out``: TEME position in km at
0 and 360 minutes after epoch.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import sgp4.api

# ``sgp4.model`` (the pure-Python model) and ``logging`` are imported only when the compiled
# extension fails the check: on a working machine the check costs no more imports than sgp4.api.

REFERENCE_LINE1 = "1 00005U 58002B   00179.78495062  .00000023  00000-0  28098-4 0  4753"
REFERENCE_LINE2 = "2 00005  34.2682 348.7242 1859667 331.7664  19.3264 10.82419157413667"
#: minutes since epoch -> TEME position (km), as printed in tcppver.out
REFERENCE_POSITIONS_KM = {
    0.0: (7022.46529266, -1400.08296755, 0.03995155),
    360.0: (-7154.03120202, -3783.17682504, -3536.19412294),
}
TOLERANCE_KM = 1e-3

#: Epoch of ``sgp4init``: days since 1949 December 31 00:00 UT (Julian date 2433281.5).
_SGP4INIT_EPOCH_JD = 2433281.5


@dataclass(frozen=True)
class Sgp4Choice:
    """What the check chose: ``mode`` (see the module docstring) and why, in one sentence."""

    mode: str
    detail: str


def reference_error_km(twoline2rv: Callable[[str, str], sgp4.api.Satrec]) -> float:
    """Largest position error (km) of ``twoline2rv(line1, line2)`` against the reference; inf on failure."""
    try:
        satrec = twoline2rv(REFERENCE_LINE1, REFERENCE_LINE2)
        worst = 0.0
        for minutes, expected in REFERENCE_POSITIONS_KM.items():
            err, position, _ = satrec.sgp4_tsince(minutes)
            if err != 0:
                return math.inf
            worst = max(worst, math.dist(position, expected))
        return worst if math.isfinite(worst) else math.inf
    except Exception:  # a broken extension may raise anything; that is a failed check
        return math.inf


def _note(message: str) -> None:
    import logging

    logging.getLogger(__name__).info("%s", message)


def python_parsed_twoline2rv(cls: type, line1: str, line2: str, whichconst: int = sgp4.api.WGS72) -> Any:
    """A ``cls`` (compiled ``Satrec``) initialised with ``sgp4init`` from the pure-Python TLE reader."""
    from sgp4 import model as python_model

    parsed = python_model.Satrec.twoline2rv(line1, line2, whichconst)
    satrec = cls()
    epoch = (parsed.jdsatepoch - _SGP4INIT_EPOCH_JD) + parsed.jdsatepochF
    satrec.sgp4init(whichconst, "i", parsed.satnum, epoch, parsed.bstar, parsed.ndot, parsed.nddot,
                    parsed.ecco, parsed.argpo, parsed.inclo, parsed.mo, parsed.no_kozai, parsed.nodeo)
    return satrec


def ensure_working_sgp4() -> Sgp4Choice:
    """Check ``sgp4`` and switch to the first working mode; safe to call more than once."""
    compiled = getattr(sgp4.api, "accelerated", False)
    if not compiled:
        return Sgp4Choice("python", "sgp4 has no compiled extension here: its pure-Python model is in use")
    satrec_cls = sgp4.api.Satrec
    if getattr(satrec_cls, "_nfw_python_parser", False):
        return Sgp4Choice("compiled-python-parser", "already switched")
    error = reference_error_km(lambda a, b: satrec_cls.twoline2rv(a, b, sgp4.api.WGS72))
    if error <= TOLERANCE_KM:
        return Sgp4Choice("compiled", f"sgp4's compiled extension agrees with the reference ({error * 1e6:.1f} mm)")
    mixed = reference_error_km(lambda a, b: python_parsed_twoline2rv(satrec_cls, a, b))
    if mixed <= TOLERANCE_KM:
        satrec_cls.twoline2rv = classmethod(python_parsed_twoline2rv)
        satrec_cls._nfw_python_parser = True
        choice = Sgp4Choice("compiled-python-parser",
                            f"sgp4's compiled TLE reader is wrong here (error {error:.3g} km): TLEs are read "
                            "by sgp4's pure-Python reader, the compiled propagator is kept")
        _note(choice.detail)
        return choice
    from sgp4 import model as python_model

    sgp4.api.Satrec, sgp4.api.SatrecArray = python_model.Satrec, python_model.SatrecArray
    sgp4.api.accelerated = False
    choice = Sgp4Choice("python", f"sgp4's compiled extension is wrong here (error {error:.3g} km, "
                        f"with the Python reader {mixed:.3g} km): using its pure-Python model (slower)")
    _note(choice.detail)
    return choice
