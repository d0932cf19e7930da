"""File errors read as sentences about the file (#25 item 9): no raw ``Errno``, and no "line 0" for a problem that
belongs to the whole file or to a JSON entry (which has a number, not a line)."""

from __future__ import annotations

import json

import pytest

from nfwserver.app.element_sources import SourceError, parse_source
from nfwserver.cli import main
from nfwserver.tracking.elements import load_element_file, load_elements

PASSES = ["passes", "--observer", "JO02ae", "--hours", "1"]


def test_a_missing_horizon_file_is_one_sentence_without_errno(tmp_path, capsys, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    assert main([*PASSES, "--horizon", "x.txt"]) == 1
    assert capsys.readouterr().err == "nfwserver: --horizon: no such file: x.txt\n"


def test_a_horizon_that_is_not_a_regular_file_is_refused_without_blocking(tmp_path, capsys) -> None:
    assert main([*PASSES, "--horizon", str(tmp_path)]) == 1
    assert capsys.readouterr().err == f"nfwserver: --horizon: {tmp_path} is not a regular file\n"


def test_a_bad_horizon_line_is_named(tmp_path, capsys) -> None:
    horizon = tmp_path / "h.txt"
    horizon.write_text("0 5\n90 x\n")
    assert main([*PASSES, "--horizon", str(horizon)]) == 1
    assert capsys.readouterr().err == f"nfwserver: --horizon: {horizon} line 2: '90 x' is not two numbers\n"


def test_an_unreadable_element_file_names_no_line(tmp_path) -> None:
    missing = tmp_path / "gone.txt"
    (rejection,) = load_element_file(missing).rejected
    assert str(rejection) == f"{missing}: cannot read the file (no such file or directory)"


def test_json_entries_are_named_by_number_not_by_a_made_up_line(tmp_path) -> None:
    text = json.dumps([{"OBJECT_NAME": "A"}, 5, {"OBJECT_NAME": "C"}])
    rejected = [str(r) for r in load_elements(text.encode(), source="x.json").rejected]
    assert rejected == ["x.json: JSON entry 1: OMM record lacks NORAD_CAT_ID",
                        "x.json: JSON entry 2 is not an OMM object",
                        "x.json: JSON entry 3: OMM record lacks NORAD_CAT_ID"]
    with pytest.raises(SourceError) as info:
        parse_source(text.encode(), "x.json")
    assert str(info.value) == ("x.json holds no element sets (first problem: JSON entry 1: OMM record lacks "
                               "NORAD_CAT_ID)")
