"""Unpack Windows wheels into the Wine prefix's site-packages (run by tools/wine/setup with Linux Python).

A wheel is a zip of its import packages plus ``NAME.dist-info``; ``NAME.data/purelib`` and
``NAME.data/platlib`` also belong in site-packages, other ``.data`` parts (scripts, headers) are
not needed to import.  Usage: ``python3 unpack_wheels.py SITE_PACKAGES WHEEL...``.
"""

from __future__ import annotations

import sys
import zipfile
from pathlib import Path


def unpack(wheel: Path, site: Path) -> int:
    """Extract ``wheel`` into ``site``; returns the number of files written."""
    count = 0
    with zipfile.ZipFile(wheel) as archive:
        for member in archive.infolist():
            if member.is_dir():
                continue
            parts = member.filename.split("/")
            if parts[0].endswith(".data"):
                if len(parts) < 3 or parts[1] not in ("purelib", "platlib"):
                    continue
                parts = parts[2:]
            target = site.joinpath(*parts)
            if not target.resolve().is_relative_to(site.resolve()):
                raise SystemExit(f"{wheel.name}: refusing to write outside site-packages: {member.filename}")
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(archive.read(member))
            count += 1
    return count


def main(argv: list[str]) -> int:
    site = Path(argv[0])
    site.mkdir(parents=True, exist_ok=True)
    for name in argv[1:]:
        print(f"  {Path(name).name}: {unpack(Path(name), site)} files")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
