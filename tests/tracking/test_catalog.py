"""Catalog update semantics, element age, decay detection and DDE names."""

from __future__ import annotations

import dataclasses
from datetime import datetime, timedelta, timezone

import pytest

from nfwserver.tracking.catalog import Catalog
from nfwserver.tracking.elements import ElementSet, load_element_file, load_elements
from nfwserver.tracking.tle import parse_tle
from tests.conftest import DATA

VISUAL = load_element_file(DATA / "visual.txt").sets


def _shifted(es: ElementSet, days: float) -> ElementSet:
    fields = parse_tle(es.line1, es.line2)
    fields = dataclasses.replace(fields, epoch=fields.epoch + timedelta(days=days))
    return ElementSet.from_fields(es.name, fields, "shifted")


def test_update_replaces_only_with_newer_epochs() -> None:
    cat = Catalog(VISUAL[:10])
    first = VISUAL[0]
    older, newer = _shifted(first, -1.0), _shifted(first, +0.5)
    summary = cat.update([older, VISUAL[10]])
    assert summary.added == [VISUAL[10].catalog_number]
    assert summary.not_newer == [first.catalog_number]
    assert cat.get(first.catalog_number).elements.epoch == first.epoch
    summary = cat.update([newer, first])
    assert summary.updated == [first.catalog_number]
    assert summary.not_newer == [first.catalog_number]  # the same epoch again is not newer
    assert cat.get(first.catalog_number).elements.epoch == newer.epoch
    assert len(cat) == 11 and first.catalog_number in cat


def test_age_and_decay() -> None:
    cat = Catalog(VISUAL)
    sat = cat.get(VISUAL[0].catalog_number)
    assert sat.age_days(sat.elements.epoch + timedelta(days=3, hours=6)) == pytest.approx(3.25)
    assert not any(s.is_decayed for s in cat)
    decayed_line2 = "2 99999  51.6000 100.0000 0300000 100.0000 100.0000 16.90000000    10"
    from nfwserver.tracking.tle import tle_checksum

    line1 = "1 99999U 26001A   26127.50000000  .00000000  00000+0  00000+0 0  999"
    text = f"{line1}{tle_checksum(line1)}\n{decayed_line2[:68]}{tle_checksum(decayed_line2)}\n"
    (es,) = load_elements(text).sets
    low = Catalog([es]).get(99999)
    assert low.perigee_height_km < 0 and low.is_decayed


def test_dde_names_are_unique_valid_and_overridable() -> None:
    cat = Catalog(load_element_file(DATA / "active.txt").sets)
    names = [s.dde_name for s in cat]
    assert len({n.upper() for n in names}) == len(names) == 15347
    assert all(0 < len(n) <= 12 and " " not in n and n.isascii() and n.isprintable() for n in names)
    assert cat.get(25544).dde_name == "ISS"
    assert cat.find("so-50").name == "SAUDISAT 1C (SO-50)"
    assert cat.find("25544").dde_name == "ISS"
    assert cat.find("iss (zarya)").catalog_number == 25544
    assert cat.find("no such satellite") is None
    cat.set_dde_name(25544, "ISS-ARISS")
    assert cat.get(25544).dde_name == "ISS-ARISS"
    assert cat.find("ISS-ARISS").catalog_number == 25544
    with pytest.raises(ValueError):
        cat.set_dde_name(25544, "TWO WORDS")
    with pytest.raises(ValueError):
        cat.set_dde_name(27607, "ISS-ARISS")  # held by another override
    with pytest.raises(ValueError):
        cat.set_dde_name(27607, "THIRTEEN-CHAR")


def test_names_do_not_depend_on_load_order() -> None:
    sets = load_element_file(DATA / "active.txt").sets[:3000]
    a = {s.catalog_number: s.dde_name for s in Catalog(sets)}
    b = {s.catalog_number: s.dde_name for s in Catalog(list(reversed(sets)))}
    half = Catalog(sets[:1500])
    half.update(sets[1500:])
    assert a == b == {s.catalog_number: s.dde_name for s in half}


def test_epoch_is_utc() -> None:
    assert all(s.epoch.tzinfo == timezone.utc for s in VISUAL)
    assert min(s.epoch for s in VISUAL) > datetime(2026, 4, 1, tzinfo=timezone.utc)


def test_dde_names_are_assigned_when_first_needed(monkeypatch) -> None:
    import nfwserver.tracking.catalog as catalog_module

    calls = []
    real = catalog_module.assign_dde_names
    monkeypatch.setattr(catalog_module, "assign_dde_names", lambda *a: calls.append(1) or real(*a))
    cat = Catalog(VISUAL, dde_names={25544: "SPACE-STN"})
    sets = cat.element_sets()
    assert [s.catalog_number for s in sets] == sorted(s.catalog_number for s in VISUAL)
    assert len(cat) == len(VISUAL) and 25544 in cat
    assert calls == []  # a catalog used for its element sets (a pass search) makes no DDE names
    assert cat.get(25544).dde_name == "SPACE-STN" and cat.find("SPACE-STN").catalog_number == 25544
    assert len(calls) == 1
    cat.satellites()
    assert len(calls) == 1  # made once
    cat.update([VISUAL[0]])
    assert len(calls) == 1  # an update that changes nothing makes nothing
    cat.update([_shifted(VISUAL[0], 1.0)])
    assert len(calls) == 2  # once read, names are made by the writer, before the swap (never by a reader)
    assert cat.get(VISUAL[0].catalog_number).elements.epoch > VISUAL[0].epoch
    assert len(calls) == 2


@pytest.mark.parametrize("named_first", [False, True])
def test_a_new_dde_name_keeps_every_satellite(named_first) -> None:
    """A name given on a running catalog (a live reload of [satellites] names) once emptied it: the swap
    released the 'old' table entry by entry, and with the element sets unchanged the old table was the new."""
    cat = Catalog(VISUAL)
    if named_first:
        assert cat.get(25544) is not None
    cat.set_dde_name(25544, "ARISS")
    assert len(cat) == len(VISUAL) and len(cat.element_sets()) == len(VISUAL)
    iss = cat.get(25544)
    assert iss is not None and iss.dde_name == "ARISS" and cat.find("ARISS") is iss
    assert len(cat.satellites()) == len(VISUAL)


def test_a_reader_holding_the_previous_tables_finds_them_whole_after_an_update() -> None:
    """An update publishes new tables and releases the old ones gradually without changing them: a reader in
    the middle of a lookup (find() walks the table it took) never sees it shrink."""
    cat = Catalog(VISUAL)
    satellites, elements = cat._named(), cat._elements  # what a reader took just before the update
    before = dict(satellites), dict(elements)
    cat.update([_shifted(es, 0.5) for es in VISUAL[:20]])
    assert (satellites, elements) == before
    assert cat.get(VISUAL[0].catalog_number).elements.epoch > VISUAL[0].epoch
