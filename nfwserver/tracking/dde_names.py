"""Short satellite names for the DDE string: at most 12 characters, no spaces, printable ASCII.

DDE clients take the first space-separated word of Nova's string as the satellite name, and
Nova's names are at most 12 characters, so each satellite gets a short name derived from its
element name.  Candidates, best first:

1. an amateur designator in parentheses: ``SAUDISAT 1C (SO-50)`` -> ``SO-50``,
   ``JAS-2 (FO-29)`` -> ``FO-29``;
2. an amateur designator opening the name: ``RS-44 & BREEZE-KM R/B`` -> ``RS-44``;
3. the name before any parentheses, blanks turned into ``-``: ``ISS (ZARYA)`` -> ``ISS``,
   ``NOAA 19`` -> ``NOAA-19``;
4. that name joined with the parenthesised part: ``ISS (UNITY)`` -> ``ISS-UNITY``;
5. the shortened name with the catalog number (``STARLI-44723``), or the bare catalog number for
   a set without a name.

Characters outside ``A-Z a-z 0-9 - _ . + /`` are dropped and every candidate is cut to 12
characters.  Within a catalog, names are unique: satellites are taken in ascending catalog
number and each receives its first candidate no lower-numbered satellite holds (the last
candidate contains the catalog number, so it is always free).  A user's override always wins and
is never given to another satellite.

Well-known satellites (:data:`WELL_KNOWN_NAMES`: every bundled satellite and every one with a
built-in radio channel) keep the name clients know them by whatever their element sets call
them: CelesTrak names AO-91 ``RADFXSAT (FOX-1B)`` and other sources give RS-44 the name of its
rocket stage, yet a client configured for ``AO-91`` or ``RS-44`` must keep receiving that name
after an element update.  Only a user's override comes before them.
"""

from __future__ import annotations

import re
from collections.abc import Iterator

MAX_LENGTH = 12
_ALLOWED = re.compile(r"[^A-Za-z0-9_.+/-]")
_AMATEUR = re.compile(r"^[A-Z]{1,3}-?\d{1,3}[A-Z]?$")
_PAREN = re.compile(r"\(([^)]*)\)")
_BLANKS = re.compile(r"\s+")
_DASHES = re.compile(r"-{2,}")
_WORD_END = re.compile(r"[\s&/]+")
#: Text that the substitutions of :func:`sanitize` would only turn blanks into dashes in: words of allowed
#: characters other than ``-``, each separated by one blank or one ``-``.
_PLAIN = re.compile(r"[A-Za-z0-9_.+/]+(?:[ -][A-Za-z0-9_.+/]+)*")
_DIGITS = frozenset("0123456789")


def sanitize(text: str) -> str:
    """``text`` with blanks as ``-``, other unusable characters dropped, at most 12 characters.

    A long name that ends in a number keeps the number whole and shortens what precedes it
    (``STARLINK-1008`` -> ``STARLIN-1008``); other long names are cut.
    """
    text = text.strip()
    if _PLAIN.fullmatch(text):  # most names: one match instead of three substitutions
        text = text.replace(" ", "-")
    else:
        text = _BLANKS.sub("-", text)
        text = _ALLOWED.sub("", text)
        text = _DASHES.sub("-", text).strip("-")
    if len(text) > MAX_LENGTH:
        head, sep, tail = text.rpartition("-")
        if sep and head and not _DIGITS.isdisjoint(tail) and len(tail) <= MAX_LENGTH - 4:  # text is ASCII here
            return head[: MAX_LENGTH - len(tail) - 1].rstrip("-") + "-" + tail
    return text[:MAX_LENGTH].rstrip("-")


#: Stable DDE names by catalog number, the names amateur operators and their clients use.
WELL_KNOWN_NAMES: dict[int, str] = {
    7530: "AO-7", 14129: "AO-10", 14781: "UO-11", 20442: "LO-19", 22825: "AO-27", 22826: "IO-26",
    24278: "FO-29", 25544: "ISS", 26931: "NO-44", 27607: "SO-50", 27844: "CO-55", 27848: "CO-57",
    32785: "CO-65", 32791: "CO-66", 35932: "SWISSCUBE", 39440: "LO-74", 39444: "AO-73", 40069: "METEOR-M-2",
    40908: "LILACSAT-2", 40967: "AO-85", 41847: "CAS-2T", 43013: "NOAA-20", 43017: "AO-91", 43770: "AO-95",
    43803: "JO-97", 44387: "METEOR-M2-2", 44879: "CAS-6", 44909: "RS-44", 48274: "CSS", 50466: "CAS-9",
    53109: "IO-117", 54234: "NOAA-21", 57166: "METEOR-M2-3", 59051: "METEOR-M2-4", 61781: "AO-123",
    63213: "TEVEL2-4", 63214: "TEVEL2-5", 63215: "TEVEL2-6", 63217: "TEVEL2-1", 63218: "TEVEL2-3",
    63219: "TEVEL2-2", 63237: "TEVEL2-9", 63238: "TEVEL2-7", 63239: "TEVEL2-8",
}


def validate_dde_name(name: str) -> str:
    """Return ``name`` if usable as a DDE satellite name, else raise :class:`ValueError`."""
    if not name or len(name) > MAX_LENGTH:
        raise ValueError(f"DDE name {name!r} must have 1 to {MAX_LENGTH} characters")
    if not name.isascii() or not name.isprintable() or " " in name:
        raise ValueError(f"DDE name {name!r} must be printable ASCII without spaces")
    return name


def name_candidates(element_name: str, catalog_number: int) -> list[str]:
    """Candidate DDE names for a satellite, best first (see the module docstring)."""
    return list(_candidates(element_name, catalog_number))


def _candidates(element_name: str, catalog_number: int) -> Iterator[str]:
    """The candidates of :func:`name_candidates`, each made when asked for (a catalog's satellites mostly
    take their first)."""
    name = element_name.strip()
    if name.startswith("0 "):
        name = name[2:]
    if "(" in name:
        inner = [p.strip() for p in _PAREN.findall(name)]
        main = _PAREN.sub(" ", name).strip()
    else:
        inner, main = [], name.strip()
    given: set[str] = {""}

    def fresh(cand: str) -> bool:
        if cand in given:
            return False
        given.add(cand)
        return True

    for part in inner:
        if _AMATEUR.match(part.upper()) and fresh(cand := sanitize(part)):
            yield cand
    first_word = _WORD_END.split(main, maxsplit=1)[0] if main else ""
    if first_word != main and _AMATEUR.match(first_word.upper()) and fresh(cand := sanitize(first_word)):
        yield cand
    if main:
        if fresh(cand := sanitize(main)):
            yield cand
        if inner and fresh(cand := sanitize(main + "-" + "-".join(inner))):
            yield cand
    number = str(catalog_number)
    base = sanitize(main or name)[: MAX_LENGTH - len(number) - 1].rstrip("-")
    if fresh(cand := f"{base}-{number}" if base else number):
        yield cand


def _plain_first(element_name: str) -> str:
    """The first of :func:`_candidates` for a name without parentheses whose first word is no amateur designator
    (the name itself, sanitised), else "" (the caller then asks :func:`_candidates`)."""
    name = element_name.strip()
    if "(" in name or name.startswith("0 ") or not name:
        return ""
    first_word = _WORD_END.split(name, maxsplit=1)[0]
    if first_word != name and _AMATEUR.match(first_word.upper()):
        return ""
    return sanitize(name)


def assign_dde_names(names: dict[int, str], overrides: dict[int, str] | None = None) -> dict[int, str]:
    """Unique DDE names for ``{catalog_number: element_name}``: overrides first, then the
    well-known names, then derived names (module docstring)."""
    overrides = overrides or {}
    taken = {n.upper() for n in overrides.values()}
    result = dict(overrides)
    for catnr in sorted(names):
        known = WELL_KNOWN_NAMES.get(catnr)
        if catnr not in result and known is not None and known.upper() not in taken:
            taken.add(known.upper())
            result[catnr] = known
    for catnr in sorted(names):
        if catnr in result:
            continue
        cand = _plain_first(names[catnr])  # most names: their first candidate, without the generator
        if cand and cand.upper() not in taken:
            taken.add(cand.upper())
            result[catnr] = cand
            continue
        for cand in _candidates(names[catnr], catnr):
            if cand.upper() not in taken:
                break
        else:  # pragma: no cover - the last candidate holds the unique catalog number
            cand = str(catnr)
        taken.add(cand.upper())
        result[catnr] = cand
    return {k: result[k] for k in names}
