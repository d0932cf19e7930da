"""docs/AUTOTRACK.md's worked example is the command's real output."""

from __future__ import annotations

import re
import shlex

import pytest

from nfwserver.cli import main
from tests.conftest import ROOT

DOC = (ROOT / "docs" / "AUTOTRACK.md").read_text(encoding="utf-8")


def test_the_worked_example_is_the_output_of_its_command(monkeypatch, capsys: pytest.CaptureFixture[str]) -> None:
    blocks = [body for _, body in re.findall(r"^```(\w*)\n(.*?)^```", DOC, re.S | re.M)]
    example = next(b for b in blocks if b.startswith("$ nfwserver schedule"))
    command, *shown = example.splitlines()
    argv = shlex.split(command)[3:]  # after "$ nfwserver schedule"
    monkeypatch.chdir(ROOT)
    assert main(["schedule", *argv]) == 0
    assert capsys.readouterr().out.splitlines() == shown
    slow = next(b for b in blocks if "min_gap_s 900" in b).splitlines()
    assert main(["schedule", *argv, "--min-gap", "900"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert all(line in out for line in slow)
    assert [line for line in out if "too close" in line] == slow
