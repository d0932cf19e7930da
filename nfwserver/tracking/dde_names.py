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
"""

from __future__ import annotations

import re

MAX_LENGTH = 12
_ALLOWED = re.compile(r"[^A-Za-z0-9_.+/-]")
_AMATEUR = re.compile(r"^[A-Z]{1,3}-?\d{1,3}[A-Z]?$")
_PAREN = re.compile(r"\(([^)]*)\)")


def sanitize(text: str) -> str:
    """``text`` with blanks as ``-``, other unusable characters dropped, at most 12 characters.

    A long name that ends in a number keeps the number whole and shortens what precedes it
    (``STARLINK-1008`` -> ``STARLIN-1008``); other long names are cut.
    """
    text = re.sub(r"\s+", "-", text.strip())
    text = _ALLOWED.sub("", text)
    text = re.sub(r"-{2,}", "-", text).strip("-")
    if len(text) > MAX_LENGTH:
        head, sep, tail = text.rpartition("-")
        if sep and head and any(c.isdigit() for c in tail) and len(tail) <= MAX_LENGTH - 4:
            return head[: MAX_LENGTH - len(tail) - 1].rstrip("-") + "-" + tail
    return text[:MAX_LENGTH].rstrip("-")


def validate_dde_name(name: str) -> str:
    """Return ``name`` if usable as a DDE satellite name, else raise :class:`ValueError`."""
    if not name or len(name) > MAX_LENGTH:
        raise ValueError(f"DDE name {name!r} must have 1 to {MAX_LENGTH} characters")
    if not name.isascii() or not name.isprintable() or " " in name:
        raise ValueError(f"DDE name {name!r} must be printable ASCII without spaces")
    return name


def name_candidates(element_name: str, catalog_number: int) -> list[str]:
    """Candidate DDE names for a satellite, best first (see the module docstring)."""
    name = element_name.strip()
    if name.startswith("0 "):
        name = name[2:]
    inner = [p.strip() for p in _PAREN.findall(name)]
    main = _PAREN.sub(" ", name).strip()
    out: list[str] = []
    for part in inner:
        if _AMATEUR.match(part.upper()):
            out.append(sanitize(part))
    first_word = re.split(r"[\s&/]+", main, maxsplit=1)[0] if main else ""
    if first_word != main and _AMATEUR.match(first_word.upper()):
        out.append(sanitize(first_word))
    if main:
        out.append(sanitize(main))
        if inner:
            out.append(sanitize(main + "-" + "-".join(inner)))
    number = str(catalog_number)
    base = sanitize(main or name)[: MAX_LENGTH - len(number) - 1].rstrip("-")
    out.append(f"{base}-{number}" if base else number)
    unique = []
    for cand in out:
        if cand and cand not in unique:
            unique.append(cand)
    return unique


def dde_name_for(element_name: str, catalog_number: int) -> str:
    """The preferred DDE name of one satellite, ignoring other satellites."""
    return name_candidates(element_name, catalog_number)[0]


def assign_dde_names(names: dict[int, str], overrides: dict[int, str] | None = None) -> dict[int, str]:
    """Unique DDE names for ``{catalog_number: element_name}``, overrides first (module docstring)."""
    overrides = overrides or {}
    taken = {n.upper() for n in overrides.values()}
    result = dict(overrides)
    for catnr in sorted(names):
        if catnr in overrides:
            continue
        for cand in name_candidates(names[catnr], catnr):
            if cand.upper() not in taken:
                break
        else:  # pragma: no cover - the last candidate holds the unique catalog number
            cand = str(catnr)
        taken.add(cand.upper())
        result[catnr] = cand
    return {k: result[k] for k in names}
