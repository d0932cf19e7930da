"""The lazy package faces are typed (issue 36 item 5): each name a package serves on first use is also
imported under TYPE_CHECKING, so ``from nfwserver.core import StationCore`` is the class to mypy, not
``object``; at run time the package still imports nothing until a name is used."""

from __future__ import annotations

import ast
import importlib
import subprocess
import sys

import pytest

from tests.conftest import ROOT

LAZY = ("app", "config", "console", "core", "dde", "dialects", "hamlib", "radio", "rotor", "tcp", "tracking")


def _typed_names(package: str) -> dict[str, str]:
    """Name -> module of the imports under ``if TYPE_CHECKING:`` in the package's ``__init__``."""
    tree = ast.parse((ROOT / "nfwserver" / package / "__init__.py").read_text(encoding="utf-8"))
    names: dict[str, str] = {}
    for node in tree.body:
        if isinstance(node, ast.If) and isinstance(node.test, ast.Name) and node.test.id == "TYPE_CHECKING":
            for imp in node.body:
                assert isinstance(imp, ast.ImportFrom) and imp.module is not None
                for alias in imp.names:
                    assert alias.asname == alias.name, "re-exported explicitly (name as name)"
                    names[alias.name] = imp.module.rsplit(".", 1)[1]
    return names


@pytest.mark.parametrize("package", LAZY)
def test_every_lazy_name_is_typed_from_its_module(package) -> None:
    exports = importlib.import_module(f"nfwserver.{package}")._EXPORTS
    assert _typed_names(package) == exports


def test_mypy_sees_the_class_through_the_package(tmp_path) -> None:
    probe = tmp_path / "probe.py"
    probe.write_text("from nfwserver.core import StationCore\nreveal_type(StationCore)\n")
    done = subprocess.run([sys.executable, "-m", "mypy", "--no-incremental", str(probe)], cwd=ROOT,
                          capture_output=True, text=True, timeout=300)
    assert "nfwserver.core.station_core.StationCore" in done.stdout, done.stdout


def test_importing_a_package_loads_none_of_its_modules() -> None:
    code = "import sys, nfwserver.core; print(sorted(m for m in sys.modules if m.startswith('nfwserver.core.')))"
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert done.stdout.strip() == "[]", done.stdout
