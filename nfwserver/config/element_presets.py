"""Named element sources: CelesTrak's GP groups (as TLE, OMM JSON or OMM CSV) and AMSAT's bare TLE file.

A preset is a name a user can put in ``[elements] sources`` or give to ``nfwserver elements update``
(``amateur``, ``weather-json``, ``amsat``) instead of a URL.  ``nfwserver elements sources`` lists them.

URLs follow each provider's documentation: CelesTrak's ``gp.php?GROUP=<group>&FORMAT=<tle|json|csv>``
under ``https://celestrak.org/NORAD/elements/`` (https://celestrak.org/NORAD/documentation/gp-data-formats.php)
and AMSAT's ``nasabare.txt`` under ``https://www.amsat.org/tle/current/``.  :meth:`Preset.url` takes another
base URL (``[elements] preset_mirror``: a local mirror, or a test server), under which the same paths are asked
for.  CelesTrak asks clients not to fetch a group more than once every two hours; the station's refresh
(``[elements] refresh_hours``, default 24) stays well within that.
"""

from __future__ import annotations

from dataclasses import dataclass

CELESTRAK_BASE = "https://celestrak.org/NORAD/elements"
AMSAT_BASE = "https://www.amsat.org/tle/current"

#: CelesTrak GP groups offered as presets: (group, what it holds).
CELESTRAK_GROUPS: tuple[tuple[str, str], ...] = (
    ("amateur", "amateur radio satellites"),
    ("stations", "space stations (ISS, CSS)"),
    ("visual", "the 100 (or so) brightest satellites"),
    ("weather", "weather satellites"),
    ("noaa", "NOAA satellites"),
    ("goes", "GOES satellites"),
    ("cubesat", "CubeSats"),
    ("satnogs", "satellites tracked by SatNOGS"),
    ("education", "education satellites"),
    ("engineering", "engineering satellites"),
    ("science", "science satellites"),
    ("resource", "earth resources satellites"),
    ("gnss", "navigation satellites (GPS, GLONASS, Galileo, BeiDou)"),
    ("geo", "the geostationary belt"),
    ("last-30-days", "objects launched in the last 30 days"),
    ("active", "every active satellite (about 15,000 objects)"),
)
#: Suffix of a preset's name -> CelesTrak FORMAT value and the form it names.
FORMATS: tuple[tuple[str, str, str], ...] = (("", "tle", "TLE"), ("-json", "json", "OMM JSON"),
                                             ("-csv", "csv", "OMM CSV"))


@dataclass(frozen=True)
class Preset:
    """One named source: ``path`` is appended to the provider's base URL."""

    name: str
    provider: str  #: "CelesTrak" or "AMSAT"
    form: str  #: "TLE", "OMM JSON" or "OMM CSV"
    what: str
    path: str

    def url(self, base: str | None = None) -> str:
        """The URL to fetch, under ``base`` when given (else the provider's own site)."""
        root = base if base else (CELESTRAK_BASE if self.provider == "CelesTrak" else AMSAT_BASE)
        return f"{root.rstrip('/')}/{self.path}"

    @property
    def label(self) -> str:
        """How messages name the preset: ``amateur (CelesTrak, TLE)``."""
        return f"{self.name} ({self.provider}, {self.form})"


PRESETS: dict[str, Preset] = {
    **{f"{group}{suffix}": Preset(f"{group}{suffix}", "CelesTrak", form, what,
                                  f"gp.php?GROUP={group}&FORMAT={fmt}")
       for group, what in CELESTRAK_GROUPS for suffix, fmt, form in FORMATS},
    "amsat": Preset("amsat", "AMSAT", "TLE", "AMSAT's current amateur satellite elements (nasabare.txt)",
                    "nasabare.txt"),
}
#: The source ``config init`` starts a station with, and ``elements update`` uses when none is configured.
DEFAULT_PRESET = "amateur"


def preset_urls(names: tuple[str, ...] | list[str], mirror: str | None = None) -> dict[str, str]:
    """The URL of each named preset (under ``mirror`` when given), mapped to its label for messages."""
    return {PRESETS[name].url(mirror): PRESETS[name].label for name in names}
