"""The start-up sgp4 check: reference values from Vallado et al. (2006), tcppver.out, satellite 00005."""

from __future__ import annotations

import math

import sgp4.api
import sgp4.model

from nfwserver.tracking import SGP4_CHOICE
from nfwserver.tracking.sgp4_selfcheck import (
    REFERENCE_LINE1,
    REFERENCE_LINE2,
    TOLERANCE_KM,
    python_parsed_twoline2rv,
    reference_error_km,
)
from tests.conftest import DATA


def test_pure_python_model_meets_the_published_reference() -> None:
    assert reference_error_km(lambda a, b: sgp4.model.Satrec.twoline2rv(a, b)) < TOLERANCE_KM


def test_a_reader_that_loses_the_mean_motion_is_caught() -> None:
    """What Wine 8.0 does to the compiled reader: mean motion 0 -> SGP4 error; the check must fail."""
    def broken(line1: str, line2: str):
        return sgp4.model.Satrec.twoline2rv(line1, line2[:52] + " 0.00000000" + line2[63:])

    assert math.isinf(reference_error_km(broken))
    assert reference_error_km(lambda a, b: 1 / 0) == math.inf


def test_the_chosen_mode_propagates_the_catalog_like_the_pure_python_model() -> None:
    """Whatever the check chose on this machine (compiled; under Wine: compiled with the Python
    reader), positions agree with sgp4's independent pure-Python model for every set."""
    assert SGP4_CHOICE.mode in ("compiled", "compiled-python-parser", "python")
    lines = [ln for ln in (DATA / "visual.txt").read_text().splitlines() if ln[:2] in ("1 ", "2 ")]
    pairs = list(zip(lines[0::2], lines[1::2]))
    assert len(pairs) > 50
    for line1, line2 in pairs:
        ours = sgp4.api.Satrec.twoline2rv(line1, line2)
        ref = sgp4.model.Satrec.twoline2rv(line1, line2)
        for minutes in (0.0, 720.0):
            e1, r1, _ = ours.sgp4_tsince(minutes)
            e2, r2, _ = ref.sgp4_tsince(minutes)
            assert e1 == e2
            if e1 == 0:
                assert math.dist(r1, r2) < 1e-3, line1


def test_python_reader_with_compiled_propagator_when_compiled_exists() -> None:
    if not sgp4.api.accelerated:
        return
    satrec = python_parsed_twoline2rv(sgp4.api.Satrec, REFERENCE_LINE1, REFERENCE_LINE2)
    assert isinstance(satrec, sgp4.api.Satrec) and satrec.satnum == 5
    err, r, _ = satrec.sgp4_tsince(360.0)
    assert err == 0 and math.dist(r, (-7154.03120202, -3783.17682504, -3536.19412294)) < TOLERANCE_KM
