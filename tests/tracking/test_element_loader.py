"""Loading element files: every format, mixtures, junk, and malformed input."""

from __future__ import annotations

import csv
import io
import json
import math
from datetime import datetime, timezone

import pytest
from hypothesis import given
from hypothesis import strategies as st
from sgp4 import exporter
from sgp4.api import Satrec

from nfwserver.tracking.elements import load_element_file, load_elements
from tests.conftest import DATA

VISUAL = (DATA / "visual.txt").read_text()
LINES = VISUAL.splitlines()

AMSAT_W5BWF = """\
   Satellite: AO-10
   Int'l Object Number: 14129
   NASA Designation: 1983-058B
   Epoch Time, T0: 88239.30510271
     Fri Aug 26, 1988.
   Epoch Rev, K0: 1114
   Mean Anomaly, M0: 6.0030 deg
   Mean Motion, N0: 2.05882335 rev/day
   Inclination, I0: 27.1492 deg
   Eccentricity, E0: 0.6027104
   Arg Perigee, W0: 331.5568 deg
   RAAN, O0: 307.6972 deg
   Period:  699.428632 min/rev
   Increment:  174.857158 deg/rev
   Beacon, F1: 145.8100 MHz
   Decay, N1: -1.38E-06 rev/day^2
   Element Set: 352
"""

AMSAT_ARRL = """\
   KEPLERIAN BULLETIN 77   ARLK077
   FROM ARRL HEADQUARTERS

   Satellite: oscar-10

   Catalog number: 14129
   Epoch time:      88248.53312992
   Element set:     353
   Inclination:       27.1605 deg
   RA of node:       306.2255 deg
   Eccentricity:    0.6029797
   Arg of perigee:   333.9978 deg
   Mean anomaly:       5.4273 deg
   Mean motion:    2.05877131 rev/day
   Decay rate:        4.4e-07 rev/day sq
   Epoch rev:            3933
   Checksum: 311
"""


def test_whole_active_catalog_loads_without_rejections() -> None:
    result = load_element_file(DATA / "active.txt")
    assert len(result.sets) == 15347
    assert result.rejected == []
    iss = next(s for s in result.sets if s.catalog_number == 25544)
    assert iss.name == "ISS (ZARYA)"
    active = (DATA / "active.txt").read_text().splitlines()
    assert active[iss.line_number - 1].strip() == "ISS (ZARYA)"
    assert active[iss.line_number] == iss.line1


def test_bulk_loaded_sets_are_ordinary_frozen_sets_with_the_model_sgp4_builds() -> None:
    """A set read in bulk equals the one built field by field from the one-set parser, is frozen and
    hashable, and its (lazily made) model propagates exactly like sgp4's own ``twoline2rv``."""
    from dataclasses import FrozenInstanceError

    from sgp4.api import WGS72

    from nfwserver.tracking.elements import ElementSet
    from nfwserver.tracking.tle import parse_tle

    sets = load_elements(VISUAL).sets
    assert len(sets) == len(LINES) // 3
    for es in sets[:20]:
        one_by_one = ElementSet.from_fields(es.name, parse_tle(es.line1, es.line2), es.source, es.line_number,
                                            lines=(es.line1, es.line2))
        assert type(es) is ElementSet and es == one_by_one and hash(es) == hash(one_by_one)
        with pytest.raises(FrozenInstanceError):
            es.name = "changed"  # type: ignore[misc]
        reference = Satrec.twoline2rv(es.line1, es.line2, WGS72)
        assert es.satrec is es.satrec  # made once
        for minutes in (0.0, 97.5, 1440.0):
            jd, fr = reference.jdsatepoch, reference.jdsatepochF + minutes / 1440.0
            assert es.satrec.sgp4(jd, fr) == reference.sgp4(jd, fr)


def test_two_and_three_line_forms_and_0_name_lines() -> None:
    _, l1, l2 = LINES[0:3]
    text = f"{l1}\n{l2}\n0 {LINES[3].strip()}\n{LINES[4]}\n{LINES[5]}\n"
    result = load_elements(text, "mix")
    assert [s.name for s in result.sets] == ["", LINES[3].strip()]
    assert result.sets[0].line_number == 1 and result.sets[1].line_number == 3
    assert result.rejected == []


def test_amsat_examples_from_the_instanttrack_manual() -> None:
    result = load_elements(AMSAT_W5BWF + "\n" + AMSAT_ARRL, "amsat")
    assert result.rejected == []
    first, second = result.sets
    assert (first.name, first.catalog_number, first.rev_number) == ("AO-10", 14129, 1114)
    assert first.international_designator == "83058B"
    assert first.epoch == datetime(1988, 8, 26, 7, 19, 20, 874144, tzinfo=timezone.utc)
    assert first.mean_motion_rev_per_day == pytest.approx(2.05882335)
    assert first.eccentricity == pytest.approx(0.6027104)
    assert first.raan_deg == pytest.approx(307.6972)
    assert (second.name, second.catalog_number, second.rev_number) == ("oscar-10", 14129, 3933)
    assert second.arg_perigee_deg == pytest.approx(333.9978)
    # The generated TLE lines drive SGP4 exactly as a TLE with those values would.
    sat = Satrec.twoline2rv(second.line1, second.line2)
    assert sat.sgp4(2447409.5, 0.3)[1] == second.satrec.sgp4(2447409.5, 0.3)[1]


def test_amsat_set_missing_a_value_is_rejected_with_its_line() -> None:
    broken = AMSAT_ARRL.replace("   Mean motion:    2.05877131 rev/day\n", "")
    result = load_elements("junk\n" + broken, "amsat")
    assert result.sets == []
    (rej,) = result.rejected
    assert rej.line_number == 5 and "mean motion" in rej.reason


def _omm_records(count: int) -> list[dict]:
    return [
        exporter.export_omm(Satrec.twoline2rv(LINES[i + 1], LINES[i + 2]), LINES[i].strip())
        for i in range(0, 3 * count, 3)
    ]


def _assert_same_as_tle(sets, count: int) -> None:
    assert len(sets) == count
    for k, es in enumerate(sets):
        ref = Satrec.twoline2rv(LINES[3 * k + 1], LINES[3 * k + 2])
        assert es.name == LINES[3 * k].strip()
        assert es.catalog_number == ref.satnum
        for t in (0.0, 0.37, 1.9):
            ok, r_ref, _ = ref.sgp4(ref.jdsatepoch, ref.jdsatepochF + t)
            ok2, r, _ = es.satrec.sgp4(ref.jdsatepoch, ref.jdsatepochF + t)
            assert max(abs(a - b) for a, b in zip(r, r_ref)) < 1e-3  # km


def test_omm_json_as_exported_by_the_sgp4_package() -> None:
    records = _omm_records(10)
    result = load_elements(json.dumps(records), "omm.json")
    assert result.rejected == []
    _assert_same_as_tle(result.sets, 10)


def test_omm_csv_between_other_content() -> None:
    records = _omm_records(5)
    out = io.StringIO()
    writer = csv.DictWriter(out, fieldnames=list(records[0]))
    writer.writeheader()
    writer.writerows(records)
    text = "# CelesTrak CSV\n" + out.getvalue() + "\n" + "\n".join(LINES[15:18]) + "\n"
    result = load_elements(text, "omm.csv")
    assert result.rejected == []
    _assert_same_as_tle(result.sets, 6)


def test_bad_omm_entries_are_reported_and_the_rest_loads() -> None:
    records = _omm_records(3)
    records[1]["ECCENTRICITY"] = 1.5
    del records[2]["MEAN_MOTION"]
    result = load_elements(json.dumps(records + ["nonsense"]), "omm.json")
    assert len(result.sets) == 1
    reasons = [r.reason for r in result.rejected]
    assert any("eccentricity" in r for r in reasons)
    assert any("MEAN_MOTION" in r for r in reasons)
    assert any("not an OMM object" in r for r in reasons)
    assert "JSON" in load_elements("[{", "x").rejected[0].reason


def _corrupt(line: str, column: int, char: str) -> str:
    return line[:column] + char + line[column + 1 :]


def test_malformed_sets_in_a_mixture_each_get_a_line_and_reason() -> None:
    good = LINES[0:3]
    bad_sum = [LINES[3], LINES[4], _corrupt(LINES[5], 68, str((int(LINES[5][68]) + 1) % 10))]
    orphan = [LINES[7]]  # line 1 of a set without its line 2
    mismatch = [LINES[9], LINES[10], LINES[14]]
    text = "\n".join(
        ["garbage \x00\x01 text", *good, "", *bad_sum, "more junk", *orphan, "zzz", *mismatch, *LINES[18:21]]
    )
    result = load_elements(text, "f.txt")
    assert [s.catalog_number for s in result.sets] == [
        int(LINES[1][2:7]),
        int(LINES[19][2:7]),
    ]
    lines = {r.line_number: r.reason for r in result.rejected}
    assert "checksum" in lines[6]
    assert "without a following line 2" in lines[10]
    assert "differ" in lines[12]


@pytest.mark.parametrize(
    "data",
    [b"", b"\x00" * 100, bytes(range(256)) * 4, "\u00e9\u00e8 non ascii \ufffd\n1 2\n2 1".encode(), b"{not json"],
)
def test_junk_never_raises(data: bytes) -> None:
    result = load_elements(data, "junk")
    assert result.sets == []


def test_unreadable_file_is_one_rejection(tmp_path) -> None:
    result = load_element_file(tmp_path / "missing.txt")
    assert result.sets == [] and "cannot read" in result.rejected[0].reason


@given(st.binary(max_size=2000))
def test_random_bytes_never_raise(data: bytes) -> None:
    result = load_elements(data, "fuzz")
    for rej in result.rejected:
        assert rej.reason and rej.line_number >= 0


@given(st.lists(st.sampled_from(LINES[:60] + ["", "junk", "1 ", "2 x", "Satellite: X", "Mean motion: 3"]), max_size=40))
def test_random_line_mixtures_never_raise_and_account_for_every_tle(lines: list[str]) -> None:
    result = load_elements("\n".join(lines), "fuzz")
    loaded = {s.catalog_number for s in result.sets}
    for es in result.sets:
        assert es.satrec.satnum == es.catalog_number
    # Every complete valid pair present in the input is loaded.
    for a, b in zip(lines, lines[1:]):
        if a in LINES and b in LINES and a.startswith("1 ") and LINES.index(a) + 1 == LINES.index(b):
            assert int(a[2:7]) in loaded


def test_lines_split_in_pieces_match_a_whole_split(monkeypatch) -> None:
    """Text is decoded and split a piece at a time (so no single call holds the interpreter lock for long);
    CR LF pairs and UTF-8 sequences cut by a piece boundary come out as from one whole split (#23 item 16)."""
    import random

    from nfwserver.tracking import elements

    monkeypatch.setattr(elements, "_PIECE", 7)
    rng = random.Random(16)
    for _ in range(2000):
        text = "".join(rng.choice(["a", "é", "\r", "\n", "\r\n", "x", "€"]) for _ in range(rng.randint(0, 40)))
        assert elements._split_lines(text) == text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
        data = text.encode()
        cut = rng.randint(0, len(data))
        data = data[:cut] + b"\xff" + data[cut:]
        whole = data.decode("utf-8", "replace").replace("\r\n", "\n").replace("\r", "\n").split("\n")
        assert elements._split_lines(data) == whole


def test_every_value_a_set_reads_from_its_lines_is_the_one_sgp4_reads() -> None:
    """A set keeps only its lines (and name, number, epoch); its other values are read from them when asked.
    sgp4's own TLE parser is the oracle: every value of every set of a 15,000-object catalog agrees with it
    (radians and rad/min converted back to the TLE's units, which sgp4 computes from the same digits)."""
    result = load_element_file(DATA / "active.txt")
    assert len(result.sets) > 15000 and not result.rejected
    for es in result.sets:
        sat = Satrec.twoline2rv(es.line1, es.line2)
        assert es.catalog_number == sat.satnum
        assert es.eccentricity == sat.ecco
        assert es.bstar == sat.bstar
        assert es.rev_number == sat.revnum
        assert es.international_designator == sat.intldesg
        assert math.radians(es.inclination_deg) == pytest.approx(sat.inclo, rel=1e-15, abs=1e-15)
        assert math.radians(es.raan_deg) == pytest.approx(sat.nodeo, rel=1e-15, abs=1e-15)
        assert math.radians(es.arg_perigee_deg) == pytest.approx(sat.argpo, rel=1e-15, abs=1e-15)
        assert math.radians(es.mean_anomaly_deg) == pytest.approx(sat.mo, rel=1e-15, abs=1e-15)
        assert es.mean_motion_rev_per_day * 2.0 * math.pi / 1440.0 == pytest.approx(sat.no_kozai, rel=1e-15)
        jd = (es.epoch - datetime(2000, 1, 1, 12, tzinfo=timezone.utc)).total_seconds() / 86400.0 + 2451545.0
        assert jd == pytest.approx(sat.jdsatepoch + sat.jdsatepochF, abs=2e-9)  # 0.2 ms: the datetime's resolution


def test_values_of_a_generated_set_are_those_of_its_lines() -> None:
    """An AMSAT set's values are the ones its generated TLE lines hold (what SGP4 and the stored catalog
    use), not the finer ones of the text it came from."""
    first = load_elements(AMSAT_W5BWF, "amsat").sets[0]
    sat = Satrec.twoline2rv(first.line1, first.line2)
    assert first.eccentricity == sat.ecco == 0.6027104
    assert first.bstar == sat.bstar
    assert math.radians(first.mean_anomaly_deg) == pytest.approx(sat.mo, rel=1e-15)


@pytest.mark.parametrize("bulk", [True, False])
def test_a_name_line_over_40_characters_names_its_set_cut_to_40(bulk: bool) -> None:
    """#34 item 13: a name line of 41..80 characters was not taken as a name, so its set had none."""
    iss = next(s for s in load_element_file(DATA / "visual.txt").sets if s.catalog_number == 25544)
    long_name = "ISS (ZARYA) WITH A NAME LINE OF SIXTY CHARACTERS, ALL TOLD!"
    assert len(long_name) == 59
    text = f"{long_name}\n{iss.line1}\n{iss.line2}\n"
    if not bulk:  # a comment first: not the bulk 3-line form, so the line-by-line reader names it
        text = "# a header\n" + text
    sets = load_elements(text).sets
    assert [s.name for s in sets] == [long_name[:40].rstrip()]
