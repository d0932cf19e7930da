"""The ``nfwserver`` process's entry (:func:`nfwserver.cli.entry`): the command runs, and what it leaves is frozen
for the interpreter's shutdown, whichever way the command ends; :func:`~nfwserver.cli.main` alone, as tests and
benches call it in their own process, freezes nothing."""

from __future__ import annotations

import gc
import subprocess
import sys
from pathlib import Path

import pytest

from nfwserver.cli import main
from nfwserver.config.loader import toml_document
from tests.conftest import ROOT

# The module ``python -m nfwserver`` runs (the Windows launcher runs the same), then what the process left frozen.
_SCRIPT = """
import gc, runpy, sys
sys.argv = ["nfwserver", *sys.argv[1:]]
try:
    runpy.run_module("nfwserver", run_name="__main__")
except SystemExit as exc:
    print(f"exit={exc.code} frozen={gc.get_freeze_count()}", file=sys.stderr)
"""


def _run_module(*argv: str, cwd: Path = ROOT) -> tuple[subprocess.CompletedProcess[str], str]:
    done = subprocess.run([sys.executable, "-c", _SCRIPT, *argv], cwd=cwd, capture_output=True, text=True,
                          timeout=60)
    return done, done.stderr.strip().splitlines()[-1]


@pytest.mark.parametrize(("argv", "code"), [(("config", "path"), "0"),  # returns
                                            (("passes", "--help"), "0"),  # argparse's SystemExit
                                            (("no-such-command",), "2")])  # a usage error
def test_the_process_entry_freezes_what_the_command_leaves(argv: tuple[str, ...], code: str) -> None:
    done, last = _run_module(*argv)
    exit_code, frozen = (part.split("=")[1] for part in last.split())
    assert exit_code == code
    assert int(frozen) > 1000  # the modules' objects at least
    if argv == ("config", "path"):
        assert done.stdout.strip().endswith("config.toml")  # the command's own output came out whole


def test_the_installed_command_is_the_process_entry() -> None:
    project = toml_document((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    assert project["scripts"]["nfwserver"] == "nfwserver.cli:entry"


def test_main_alone_freezes_nothing(capsys: pytest.CaptureFixture[str]) -> None:
    before = gc.get_freeze_count()
    assert main(["config", "path"]) == 0
    assert capsys.readouterr().out.strip().endswith("config.toml")
    assert gc.get_freeze_count() == before  # (other tests' stations freeze their catalogs: app/long_lived.py)
