"""The program's version, derived from the repository: CHANGELOG.md's newest release plus the commits since.

A release is an entry ``## [X.Y.Z] - YYYY-MM-DD`` in ``CHANGELOG.md`` (Keep a Changelog).  The commit that
added the newest entry's heading *is* that release: it and every build of it carry ``X.Y.Z``; a build of the
*n*-th commit after it carries ``X.Y.Z.postN`` (PEP 440, so a later commit always has a higher version, and
the next release's ``X.Y.(Z+1)`` is higher than every post-release).  Nothing but the tree and its git history
goes in, so two builds of one commit carry the same version, and a fresh clone knows it without git tags.

Where the version comes from when it is asked for (:func:`package_version`):

1. ``nfwserver/_version.py``, written by every build (the wheel, the sdist, the Windows installer's stage;
   :func:`write_version_file`), where no git history travels;
2. in a git checkout (the package beside ``CHANGELOG.md`` and ``.git``): computed by :func:`describe`;
3. else the installed distribution's metadata; else ``0+unknown``.

A checkout where git cannot say (git missing, as in the Windows Python under Wine, or a shallow clone) shows
``X.Y.Z+unknown``; a *build* refuses instead (:func:`build_version` raises :class:`VersionError`), so no
build ever silently gets a made-up version.

This module imports nothing of ``nfwserver``: ``setup.py`` and ``tools/windows/build`` load it by its path
(``python3 nfwserver/release.py ROOT`` prints the version; ``--windows`` the four-number Windows form).
"""

from __future__ import annotations

import functools
import re
import subprocess
import sys
from pathlib import Path

__all__ = ["CHANGELOG", "VersionError", "build_version", "describe", "newest_release", "package_version",
           "windows_version", "write_version_file"]

CHANGELOG = "CHANGELOG.md"
VERSION_FILE = "_version.py"
#: A release's heading in Keep a Changelog form: ``## [1.2.3] - 2026-11-28``.
RELEASE_HEADING = re.compile(r"^## \[(\d+\.\d+\.\d+)\] - (\d{4}-\d{2}-\d{2})[ \t]*$", re.M)
_VERSION_LINE = re.compile(r'^VERSION = "([^"\n]+)"$', re.M)
_POST = re.compile(r"^(\d+)\.(\d+)\.(\d+)(?:\.post(\d+))?$")


class VersionError(Exception):
    """The version cannot be derived (one sentence saying why and what to do)."""


def newest_release(changelog: str) -> str:
    """``X.Y.Z`` of the first release heading in ``changelog`` (an ``[Unreleased]`` section is skipped)."""
    found = RELEASE_HEADING.search(changelog)
    if found is None:
        raise VersionError(f"{CHANGELOG} has no release entry '## [X.Y.Z] - YYYY-MM-DD'")
    return found.group(1)


def _git(root: Path, *args: str) -> str:
    try:
        done = subprocess.run(["git", "-C", str(root), *args], capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.SubprocessError) as exc:
        raise VersionError(f"git could not be run ({exc})") from None
    if done.returncode != 0:
        raise VersionError(f"git {args[0]} failed: {done.stderr.strip() or done.returncode}")
    return done.stdout.strip()


def describe(root: Path) -> str:
    """The version of the commit checked out at ``root`` (a git work tree holding ``CHANGELOG.md``)."""
    release = newest_release(_git(root, "show", f"HEAD:{CHANGELOG}"))
    if _git(root, "rev-parse", "--is-shallow-repository") == "true":
        raise VersionError("a shallow clone lacks the history the version counts: `git fetch --unshallow`")
    heading = f"## [{release}]"
    added = _git(root, "log", "-1", "--format=%H", "-S", heading, "HEAD", "--", CHANGELOG)
    if not added:
        raise VersionError(f"no commit of {CHANGELOG} adds '{heading}'")
    since = int(_git(root, "rev-list", "--count", f"{added}..HEAD"))
    return release if since == 0 else f"{release}.post{since}"


def read_version_file(package: Path) -> str | None:
    """The version a build wrote into ``package/_version.py``, or None."""
    try:
        found = _VERSION_LINE.search((package / VERSION_FILE).read_text(encoding="utf-8"))
    except OSError:
        return None
    return found.group(1) if found else None


def write_version_file(package: Path, version: str) -> Path:
    """Write ``package/_version.py`` (a build's record of its version, for installs without git history)."""
    target = package / VERSION_FILE
    target.unlink(missing_ok=True)  # never through a hard link into the source tree (sdist's release tree)
    target.write_text(f'"""Written by the build (nfwserver/release.py)."""\n\nVERSION = "{version}"\n',
                      encoding="utf-8", newline="\n")
    return target


def build_version(root: Path) -> str:
    """The version a build of the tree at ``root`` carries: from git in a checkout, else (an unpacked sdist)
    from its ``_version.py``; raises :class:`VersionError` rather than guess."""
    if (root / ".git").exists():
        return describe(root)
    written = read_version_file(root / "nfwserver")
    if written is None:
        raise VersionError(f"{root} is neither a git checkout nor an sdist with nfwserver/{VERSION_FILE}")
    return written


def windows_version(version: str) -> str:
    """``X.Y.Z.N`` for Windows' version records (four numbers up to 65535; N the post-release number)."""
    found = _POST.match(version)
    if found is None:
        raise VersionError(f"{version} is not X.Y.Z or X.Y.Z.postN")
    numbers = [int(part or 0) for part in found.groups()]
    if max(numbers) > 65535:
        raise VersionError(f"{version} does not fit Windows' version numbers (each at most 65535)")
    return ".".join(map(str, numbers))


@functools.cache
def package_version() -> str:
    """This program's version (see the module docstring for where it comes from)."""
    package = Path(__file__).resolve().parent
    written = read_version_file(package)
    if written is not None:
        return written
    root = package.parent
    if (root / ".git").exists() and (root / CHANGELOG).is_file():
        try:
            return describe(root)
        except VersionError:
            try:
                release = newest_release((root / CHANGELOG).read_text(encoding="utf-8"))
            except (OSError, VersionError):
                release = "0"
            return f"{release}+unknown"
    try:
        from importlib.metadata import PackageNotFoundError, version

        return version("nfwserver")
    except PackageNotFoundError:
        return "0+unknown"


def main(argv: list[str]) -> int:
    """``release.py ROOT [--windows]``: print the build version of ROOT (exit 1 with the reason if none)."""
    try:
        version = build_version(Path(argv[0]))
        print(windows_version(version) if argv[1:] == ["--windows"] else version)
    except (VersionError, IndexError) as exc:
        print(f"nfwserver/release.py: {exc or 'usage: release.py ROOT [--windows]'}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
