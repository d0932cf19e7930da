"""The packages that had lazy faces have none (issue 46): each name is imported from the module that defines it,
so no name is listed twice, and importing a package (which importing any of its modules does first) loads none of
its modules.  (cli's __init__ holds the command's code; commands, easycomm, fake_dde, health and web re-export
eagerly.)"""

from __future__ import annotations

import ast
import subprocess
import sys

import pytest

from tests.conftest import ROOT

PACKAGES = ("app", "config", "console", "core", "dde", "dialects", "hamlib", "radio", "rotor", "tcp", "tracking")
#: What a package's import must still do first: tracking checks sgp4 before any module imports its classes.
START_UP = {"tracking": ("SGP4_CHOICE = ensure_working_sgp4()",
                         "from nfwserver.tracking.sgp4_selfcheck import ensure_working_sgp4")}


@pytest.mark.parametrize("package", PACKAGES)
def test_a_package_init_serves_no_names(package: str) -> None:
    tree = ast.parse((ROOT / "nfwserver" / package / "__init__.py").read_text(encoding="utf-8"))
    served = [node for node in tree.body if isinstance(node, (ast.Assign, ast.FunctionDef, ast.ClassDef, ast.If))
              or (isinstance(node, ast.ImportFrom) and (node.module or "").startswith(f"nfwserver.{package}"))]
    served_text = [ast.unparse(node) for node in served]
    assert [text for text in served_text if text not in START_UP.get(package, ())] == []


def test_importing_a_package_loads_none_of_its_modules() -> None:
    code = ("import importlib, sys\n"
            f"for p in {PACKAGES!r}:\n"
            "    importlib.import_module('nfwserver.' + p)\n"
            f"print(sorted(m for m in sys.modules if any(m.startswith(f'nfwserver.{{p}}.') for p in {PACKAGES!r})\n"
            "             and m != 'nfwserver.tracking.sgp4_selfcheck'))")
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and done.stdout.strip() == "[]", done.stdout + done.stderr
