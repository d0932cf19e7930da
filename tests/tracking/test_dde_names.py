"""Deriving short DDE names from element names."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from nfwserver.tracking.dde_names import assign_dde_names, sanitize, validate_dde_name


@pytest.mark.parametrize(
    ("element_name", "expected"),
    [
        ("ISS (ZARYA)", "ISS"),
        ("SAUDISAT 1C (SO-50)", "SO-50"),
        ("JAS-2 (FO-29)", "FO-29"),
        ("OSCAR 7 (AO-7)", "AO-7"),
        ("NOAA 19", "NOAA-19"),
        ("NOAA 20 (JPSS-1)", "NOAA-20"),
        ("RS-44 & BREEZE-KM R/B", "RS-44"),
        ("XW-3 (CAS-9)", "CAS-9"),
        ("STARLINK-1008", "STARLIN-1008"),
        ("METEOR-M2 3", "METEOR-M2-3"),
        ("0 ISS (ZARYA)", "ISS"),
        ("", "12345"),
        ("   ", "12345"),
    ],
)
def test_names_operators_recognise(element_name: str, expected: str) -> None:
    assert assign_dde_names({12345: element_name}) == {12345: expected}


def test_collisions_resolved_by_catalog_number() -> None:
    names = assign_dde_names({26400: "ISS (ZVEZDA)", 25575: "ISS (UNITY)", 25544: "ISS (ZARYA)"})
    assert names == {26400: "ISS-ZVEZDA", 25575: "ISS-UNITY", 25544: "ISS"}
    names = assign_dde_names({1: "SAME", 2: "SAME", 3: "SAME"})
    assert names == {1: "SAME", 2: "SAME-2", 3: "SAME-3"}
    assert assign_dde_names({1: "SAME", 2: "SAME"}, {2: "SAME"}) == {1: "SAME-1", 2: "SAME"}


@given(st.text(max_size=60), st.integers(1, 339999))
def test_any_name_gives_a_valid_dde_name(name: str, catnr: int) -> None:
    assert validate_dde_name(assign_dde_names({catnr: name})[catnr])
    assert len(sanitize(name)) <= 12


def _sanitize_by_the_rule(text: str) -> str:
    """The rule of :func:`sanitize`'s docstring spelt out with three substitutions, one step each: blanks
    become ``-``, characters outside ``A-Z a-z 0-9 - _ . + /`` are dropped, runs of ``-`` become one and
    none opens or ends the name; then the 12-character cut that keeps a trailing number whole."""
    import re

    text = re.sub(r"\s+", "-", text.strip())
    text = re.sub(r"[^A-Za-z0-9_.+/-]", "", text)
    text = re.sub(r"-{2,}", "-", text).strip("-")
    if len(text) > 12:
        head, sep, tail = text.rpartition("-")
        if sep and head and any(c.isdigit() for c in tail) and len(tail) <= 8:
            return head[: 12 - len(tail) - 1].rstrip("-") + "-" + tail
    return text[:12].rstrip("-")


@given(st.text(alphabet=st.sampled_from("AZaz09_.+/- \t()&'é"), max_size=30))
def test_sanitize_follows_its_rule_for_any_text(text: str) -> None:
    assert sanitize(text) == _sanitize_by_the_rule(text)


def test_sanitize_follows_its_rule_for_every_name_of_a_catalog() -> None:
    from tests.conftest import DATA

    names = (DATA / "active.txt").read_text().splitlines()[0::3]
    assert len(names) > 15000
    for name in names:
        assert sanitize(name) == _sanitize_by_the_rule(name)


def _assign_by_the_rule(names: dict[int, str]) -> dict[int, str]:
    """The module docstring's rule spelt out: the well-known names first, then, in ascending catalog number, each
    satellite's first candidate (``name_candidates``, best first) that no satellite holds yet (case ignored)."""
    from nfwserver.tracking.dde_names import WELL_KNOWN_NAMES, name_candidates

    taken: set[str] = set()
    result: dict[int, str] = {}
    for catnr in sorted(names):
        known = WELL_KNOWN_NAMES.get(catnr)
        if known is not None and known.upper() not in taken:
            taken.add(known.upper())
            result[catnr] = known
    for catnr in sorted(names):
        if catnr not in result:
            result[catnr] = next(c for c in name_candidates(names[catnr], catnr) if c.upper() not in taken)
            taken.add(result[catnr].upper())
    return result


def test_a_whole_catalog_is_named_by_the_rule() -> None:
    """Every name of two catalogs, with names made to collide and the awkward shapes (amateur first words, a
    leading "0 ", blanks only, parentheses) added: the fast path for plain names gives what the rule gives."""
    from tests.conftest import DATA

    names: dict[int, str] = {}
    for file in ("active.txt", "visual.txt"):
        lines = (DATA / file).read_text().splitlines()
        names.update((int(lines[k + 1][2:7]), lines[k].strip()) for k in range(0, len(lines) - 2, 3))
    assert len(names) > 15000
    awkward = ["0 ISS", "   ", "RS-44 & BREEZE-KM R/B", "AO-7", "ISS", "STARLINK-1008", "starlink-1008", "A*B C",
               "NOAA 19", "noaa-19", "SO-50 (X)", "ISS (ZARYA)", "STARLIN-1008", "X -- Y", "FO 29 PLUS"]
    names.update((900000 + k, name) for k, name in enumerate(awkward))
    names.update((1 + k, name) for k, name in enumerate(awkward))  # the same names, before the catalog's
    assert assign_dde_names(names) == _assign_by_the_rule(names)
