"""One satellite's element set as the station holds it, and what loading text produces.

:class:`ElementSet` is a loaded set with its SGP4 model (initialised on first use); :class:`Rejection`
and :class:`LoadResult` are what :func:`nfwserver.tracking.elements.load_elements` returns.  The line
classifiers here (:data:`TLE_LIKE`, :func:`is_csv_header`) are shared by the loader and by
:meth:`ElementSet.tle_text`, which must write names the loader reads back as names.
"""

from __future__ import annotations

import re
from dataclasses import MISSING, dataclass, field, fields, make_dataclass, replace
from datetime import datetime

from sgp4.api import WGS72, Satrec

from nfwserver.tracking import amsat
from nfwserver.tracking.element_names import sanitize_element_name
from nfwserver.tracking.tle import TleFields, epoch_from_tle, exponent_field, format_tle

# A line that claims to be a TLE line: line number, blank, 5-character catalog field.
TLE_LIKE = re.compile(r"^[12] [0-9A-Z ]{4}[0-9]")
#: Longest CSV row read (characters); longer rows are rejected before the csv module sees them.
MAX_CSV_ROW = 4096
CSV_COLUMN = re.compile(r"[A-Z_]+")


def is_csv_header(line: str) -> bool:
    """True for an OMM CSV header row: upper-case column names including NORAD_CAT_ID and MEAN_MOTION."""
    if "NORAD_CAT_ID" not in line or "MEAN_MOTION" not in line or "," not in line:
        return False
    columns = [c.strip().strip('"') for c in line.strip().split(",")]
    return all(CSV_COLUMN.fullmatch(c) for c in columns)



@dataclass(frozen=True, slots=True)
class ElementSet:
    """One satellite's mean elements at an epoch, with its SGP4 model (slots: catalogs hold tens of thousands).

    The set holds its canonical TLE lines and reads every other value from them when asked (the
    ``*_deg``, ``eccentricity``, ``mean_motion_rev_per_day``, ``bstar``, ``rev_number`` and
    ``international_designator`` properties, parsed as :func:`~nfwserver.tracking.tle.parse_tle` parses
    them): the lines are what SGP4 and the stored catalog use, so the values always agree with them, and a
    loaded catalog keeps about 550 bytes a set (lines, name, number, epoch, the set) instead of 880.  Only
    the name, catalog number and epoch, which catalogs compare and sort by, are kept as values.

    The SGP4 model (:attr:`satrec`) of a set read from canonical TLE lines is initialised when first
    used: a station propagates a handful of a catalog's satellites, and the model is most of a set's
    loading time (about 3 us) and memory (about 1 KiB).  Sets from AMSAT, OMM or irregular TLE text
    get theirs at once, since initialising it is part of checking them."""

    name: str  #: name as given ("ISS (ZARYA)"), sanitised (element_names); "" when the set had none
    catalog_number: int
    epoch: datetime  #: aware UTC, on the TLE's 1e-8-day grid (as line 1 holds it)
    line1: str  #: canonical TLE line 1 (generated for AMSAT and OMM input)
    line2: str
    source: str = ""
    line_number: int = 0  #: 1-based line where the set started in ``source``
    _satrec: Satrec | None = field(default=None, compare=False, repr=False)

    @property
    def international_designator(self) -> str:
        """International designator as line 1 holds it (``98067A``), "" when blank."""
        return self.line1[9:17].strip()

    @property
    def inclination_deg(self) -> float:
        return float(self.line2[8:16])

    @property
    def raan_deg(self) -> float:
        """Right ascension of the ascending node (deg)."""
        return float(self.line2[17:25])

    @property
    def eccentricity(self) -> float:
        digits = self.line2[26:33].strip()
        return float(int(digits) / 10 ** len(digits))  # as parse_tle reads it

    @property
    def arg_perigee_deg(self) -> float:
        return float(self.line2[34:42])

    @property
    def mean_anomaly_deg(self) -> float:
        return float(self.line2[43:51])

    @property
    def mean_motion_rev_per_day(self) -> float:
        return float(self.line2[52:63])

    @property
    def bstar(self) -> float:
        """Drag term (1/earth radii)."""
        return exponent_field(self.line1[53:61], "BSTAR")

    @property
    def rev_number(self) -> int:
        """Revolution number at epoch (0 when blank)."""
        return int(self.line2[63:68].strip() or 0)

    @property
    def satrec(self) -> Satrec:
        """The initialised SGP4 model (WGS-72 constants, as the elements were fitted), made on first use."""
        satrec = self._satrec
        if satrec is None:
            satrec = Satrec.twoline2rv(self.line1, self.line2, WGS72)
            object.__setattr__(self, "_satrec", satrec)  # a cache: the same model every time
        return satrec

    def transient_satrec(self) -> Satrec:
        """The SGP4 model for one-off bulk work (a catalog-wide pass search): the one already made, or a
        new one that is not kept, so a search over many sets holds only the models it is using."""
        return self._satrec or Satrec.twoline2rv(self.line1, self.line2, WGS72)

    @classmethod
    def from_fields(cls, name: str, fields: TleFields, source: str = "", line_number: int = 0,
                    lines: tuple[str, str] | None = None) -> ElementSet:
        """Build from parsed values; ``lines`` are the original TLE lines when there were any.

        Lines generated here (AMSAT, OMM) hold the values as a TLE rounds them (the epoch on its 1e-8-day
        grid); the set reads its values from those lines, so memory, the stored catalog and SGP4 agree on
        one value (an OMM epoch or eccentricity may be finer)."""
        if lines is None:
            line1, line2 = format_tle(fields)
            fields = replace(fields, epoch=epoch_from_tle(int(line1[18:20]), float(line1[20:32])))
        else:
            line1, line2 = lines
        satrec = Satrec.twoline2rv(line1, line2, WGS72)
        return cls(name=sanitize_element_name(name), catalog_number=fields.catalog_number, epoch=fields.epoch,
                   line1=line1, line2=line2, source=source, line_number=line_number, _satrec=satrec)

    def tle_text(self) -> str:
        """The set as three lines (name, line 1, line 2), newline-terminated.

        A name that would be read back as something else (a TLE line, an AMSAT or CSV header) is
        written in CelesTrak's ``0 NAME`` form, which the loader reads as a name.
        """
        name = self.name or str(self.catalog_number)
        if TLE_LIKE.match(name) or name.startswith(("1 ", "2 ", "0 ")) or amsat.is_satellite_line(name) \
                or is_csv_header(name):
            name = "0 " + name
        return f"{name}\n{self.line1}\n{self.line2}\n"


#: ElementSet's mutable twin: the same slots in the same order.  The bulk loader fills one and makes it an
#: ElementSet by assigning its class, which skips the frozen ``__init__``'s per-field ``object.__setattr__``
#: (about 1.2 us a set, a fifth of loading a large catalog); the result is an ordinary, frozen ElementSet.
ElementSetDraft = make_dataclass(
    "ElementSetDraft",
    [(f.name, f.type) if f.default is MISSING else (f.name, f.type, field(default=f.default))
     for f in fields(ElementSet)], slots=True)


@dataclass(frozen=True)
class Rejection:
    """A set that was not loaded: where it started and why."""

    source: str
    line_number: int  #: 1-based; 0 for a problem of the whole file (it cannot be read), which names no line
    reason: str

    def where(self) -> str:
        """``source line N``, or only ``source`` for a whole-file problem."""
        return f"{self.source} line {self.line_number}" if self.line_number > 0 else self.source

    def __str__(self) -> str:
        return f"{self.where()}: {self.reason}"


@dataclass
class LoadResult:
    """What a load found: the accepted sets (file order) and the rejections."""

    sets: list[ElementSet] = field(default_factory=list)
    rejected: list[Rejection] = field(default_factory=list)
