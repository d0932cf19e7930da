"""Configuration files for stations the Windows suite starts (used on both sides of Wine).

The station tracks from ``tests/data/visual.txt`` only (no bundled sets, no element store, no
saved state), publishes at 10 Hz, and AutoTracks the ISS unless told otherwise.
"""

from __future__ import annotations

from pathlib import Path

DATA = Path(__file__).resolve().parent.parent / "data"
#: Cambridge, as in tests/dde/conftest.py
OBSERVER = "52.2053,0.1218,20"


def write_station_config(directory: Path, satellite: int = 25544, rate_hz: float = 10.0,
                         elements: Path = DATA / "visual.txt", observer: str = OBSERVER, extra: str = "",
                         state_file: str = "none") -> Path:
    """Write ``station.toml`` into ``directory`` and return its path; ``extra`` is appended TOML."""
    directory.mkdir(parents=True, exist_ok=True)
    path = directory / "station.toml"
    # TOML literal strings: Windows paths keep their backslashes.
    path.write_text(
        f"[observer]\nlocation = '{observer}'\n"
        f"[elements]\nfiles = ['{elements}']\nuse_bundled = false\nstore = 'none'\nrefresh_hours = 0\n"
        f"[server]\nrate_hz = {rate_hz:g}\nsatellite = {satellite}\nstate_file = '{state_file}'\n{extra}",
        encoding="utf-8",
    )
    return path
