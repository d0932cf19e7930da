"""Versions from the repository (#45 item 1): CHANGELOG.md's newest release plus the commits since the commit that
added it; the same for two builds of one commit, higher for a later commit, known without git tags, never a
silent made-up version.  Real git repositories in a temporary folder; PEP 440's order from ``packaging`` (an
implementation independent of ours) judges "higher"."""

from __future__ import annotations

import io
import re
import subprocess
import sys
import zipfile
from contextlib import redirect_stdout
from pathlib import Path

import pytest
from packaging.version import Version

from nfwserver.cli import main
from nfwserver.release import (
    RELEASE_HEADING,
    VersionError,
    build_version,
    describe,
    newest_release,
    package_version,
    windows_version,
)
from tests.conftest import ROOT

HEAD = "# Changelog\n\n## [Unreleased]\n\n"


def _git(repo: Path, *args: str) -> str:
    env = {"GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@example.org", "GIT_COMMITTER_NAME": "t",
           "GIT_COMMITTER_EMAIL": "t@example.org", "PATH": "/usr/bin:/bin", "HOME": str(repo)}
    return subprocess.run(["git", "-C", str(repo), *args], check=True, capture_output=True, text=True,
                          env=env).stdout.strip()


def _commit(repo: Path, name: str, text: str) -> None:
    (repo / name).write_text(text)
    _git(repo, "add", name)
    _git(repo, "commit", "-q", "-m", f"change {name}")


@pytest.fixture
def repo(tmp_path: Path) -> Path:
    work = tmp_path / "repo"
    work.mkdir()
    _git(work, "init", "-q")
    _commit(work, "code.py", "x = 1\n")
    return work


def test_the_release_commit_then_each_later_commit_counts_up(repo: Path) -> None:
    with pytest.raises(VersionError):  # no CHANGELOG.md: no version rather than a made-up one
        describe(repo)
    _commit(repo, "CHANGELOG.md", HEAD + "## [0.1.0] - 2026-11-28\n\n- first\n")
    assert describe(repo) == "0.1.0"
    seen = [Version(describe(repo))]
    for n in range(1, 4):
        _commit(repo, "code.py", f"x = {n + 1}\n")
        assert describe(repo) == describe(repo) == f"0.1.0.post{n}"  # one commit, one version
        seen.append(Version(describe(repo)))
    _commit(repo, "CHANGELOG.md", HEAD + "- coming\n\n## [0.1.0] - 2026-11-28\n\n- first\n")  # Unreleased grows
    seen.append(Version(describe(repo)))
    _commit(repo, "CHANGELOG.md", HEAD + "## [0.2.0] - 2026-12-01\n\n- coming\n\n## [0.1.0] - 2026-11-28\n")
    assert describe(repo) == "0.2.0"
    seen.append(Version(describe(repo)))
    assert seen == sorted(seen) and len(set(seen)) == len(seen)  # every later commit higher
    assert [windows_version(str(v)) for v in seen[:2]] == ["0.1.0.0", "0.1.0.1"]


def test_an_uncommitted_entry_does_not_change_the_commits_version(repo: Path) -> None:
    _commit(repo, "CHANGELOG.md", HEAD + "## [0.1.0] - 2026-11-28\n")
    _commit(repo, "code.py", "x = 2\n")
    (repo / "CHANGELOG.md").write_text(HEAD + "## [0.2.0] - 2026-12-01\n\n## [0.1.0] - 2026-11-28\n")
    assert describe(repo) == "0.1.0.post1"


def test_a_shallow_clone_is_refused_not_guessed(repo: Path, tmp_path: Path) -> None:
    _commit(repo, "CHANGELOG.md", HEAD + "## [0.1.0] - 2026-11-28\n")
    for n in range(3):
        _commit(repo, "code.py", f"x = {n + 5}\n")
    shallow = tmp_path / "shallow"
    subprocess.run(["git", "clone", "-q", "--depth", "1", f"file://{repo}", str(shallow)], check=True)
    with pytest.raises(VersionError, match="shallow"):
        build_version(shallow)
    full = tmp_path / "full"
    subprocess.run(["git", "clone", "-q", str(repo), str(full)], check=True)
    assert build_version(full) == "0.1.0.post3"  # a fresh clone, no tags: the same version


def test_a_tree_without_git_takes_the_builds_version_file_or_refuses(tmp_path: Path) -> None:
    (tmp_path / "nfwserver").mkdir()
    with pytest.raises(VersionError):
        build_version(tmp_path)
    (tmp_path / "nfwserver" / "_version.py").write_text('VERSION = "0.1.0.post7"\n')
    assert build_version(tmp_path) == "0.1.0.post7"


def test_this_checkout_shows_its_commits_version() -> None:
    if not (ROOT / ".git").exists():
        pytest.skip("not a git checkout")
    expected = describe(ROOT)
    assert RELEASE_HEADING.search((ROOT / "CHANGELOG.md").read_text())  # Keep a Changelog's release heading
    assert re.fullmatch(rf"{re.escape(newest_release((ROOT / 'CHANGELOG.md').read_text()))}(\.post\d+)?", expected)
    assert package_version() == expected
    out = io.StringIO()
    with redirect_stdout(out), pytest.raises(SystemExit) as done:
        main(["--version"])
    assert done.value.code == 0 and out.getvalue() == f"nfwserver {expected}\n"


def test_a_wheel_built_from_a_fresh_clone_carries_the_version(tmp_path: Path) -> None:
    """``pip install .`` in a clone: the wheel's metadata and its ``_version.py`` carry the commit's version."""
    if not (ROOT / ".git").exists():
        pytest.skip("not a git checkout")
    clone = tmp_path / "clone"
    subprocess.run(["git", "clone", "-q", "--no-hardlinks", str(ROOT), str(clone)], check=True)
    subprocess.run(["git", "-C", str(clone), "checkout", "-q", "--detach", _git(ROOT, "rev-parse", "HEAD")], check=True)
    expected = describe(clone)
    out = tmp_path / "wheel"
    subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w", str(out), str(clone)], check=True,
                   timeout=300)
    (wheel,) = out.glob("*.whl")
    assert wheel.name == f"nfwserver-{expected}-py3-none-any.whl"
    with zipfile.ZipFile(wheel) as archive:
        assert f'VERSION = "{expected}"' in archive.read("nfwserver/_version.py").decode()
    assert not (clone / "nfwserver" / "_version.py").exists()  # the checkout itself keeps asking git
