"""Deriving short DDE names from element names."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from nfwserver.tracking.dde_names import assign_dde_names, dde_name_for, sanitize, validate_dde_name


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
    assert dde_name_for(element_name, 12345) == expected


def test_collisions_resolved_by_catalog_number() -> None:
    names = assign_dde_names({26400: "ISS (ZVEZDA)", 25575: "ISS (UNITY)", 25544: "ISS (ZARYA)"})
    assert names == {26400: "ISS-ZVEZDA", 25575: "ISS-UNITY", 25544: "ISS"}
    names = assign_dde_names({1: "SAME", 2: "SAME", 3: "SAME"})
    assert names == {1: "SAME", 2: "SAME-2", 3: "SAME-3"}
    assert assign_dde_names({1: "SAME", 2: "SAME"}, {2: "SAME"}) == {1: "SAME-1", 2: "SAME"}


@given(st.text(max_size=60), st.integers(1, 339999))
def test_any_name_gives_a_valid_dde_name(name: str, catnr: int) -> None:
    assert validate_dde_name(dde_name_for(name, catnr))
    assert len(sanitize(name)) <= 12
