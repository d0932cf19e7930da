"""setuptools' part of the build: the version from the repository (nfwserver/release.py; pyproject.toml holds the
rest).  Every wheel and sdist gets ``nfwserver/_version.py`` with that version, so an install without git history
(a wheel, an unpacked sdist) still knows it; a tree that is neither a git checkout nor an sdist is refused."""

from __future__ import annotations

import importlib.util
from pathlib import Path
from typing import Any

from setuptools import setup
from setuptools.command.build_py import build_py
from setuptools.command.sdist import sdist

ROOT = Path(__file__).resolve().parent
_spec = importlib.util.spec_from_file_location("nfwserver_release", ROOT / "nfwserver" / "release.py")
assert _spec is not None and _spec.loader is not None
release = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(release)
VERSION = release.build_version(ROOT)


class BuildPy(build_py):
    """Also writes ``nfwserver/_version.py`` into the build (not for an editable install: a checkout asks git)."""

    def run(self) -> None:
        super().run()
        if not getattr(self, "editable_mode", False):
            release.write_version_file(Path(self.build_lib) / "nfwserver", VERSION)


class Sdist(sdist):
    """Also writes ``nfwserver/_version.py`` into the sdist, which carries no git history."""

    def make_release_tree(self, base_dir: str, files: Any) -> None:
        super().make_release_tree(base_dir, files)
        release.write_version_file(Path(base_dir) / "nfwserver", VERSION)


setup(version=VERSION, cmdclass={"build_py": BuildPy, "sdist": Sdist})
