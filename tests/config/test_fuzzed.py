"""Arbitrary values for every key of the table: accepted, or refused with one problem per bad key — never a crash."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from nfwserver.config.loader import ConfigError, parse_config
from nfwserver.config.render import toml_value
from nfwserver.config.table import SETTINGS

_scalar = st.one_of(st.booleans(), st.integers(-10**12, 10**12), st.floats(allow_nan=True, allow_infinity=True),
                    st.text(max_size=12), st.sampled_from(["127.0.0.1", "0.0.0.0", "::1", "10.0.0.0/8", "/dev/null",
                                                           "auto", "on", "doppler", "JO02ae", "none", "default"]))
_value = st.one_of(_scalar, st.lists(_scalar, max_size=3), st.lists(st.lists(_scalar, max_size=3), max_size=3),
                   st.dictionaries(st.text(max_size=5), _scalar, max_size=3))
_entries = st.lists(st.tuples(st.sampled_from(SETTINGS), _value), max_size=6,
                    unique_by=lambda e: (e[0].section, e[0].key))


@settings(max_examples=200)
@given(_entries)
def test_fuzzed_values_for_every_key(entries) -> None:
    sections: dict[str, list[str]] = {}
    for entry, value in entries:
        sections.setdefault(entry.section, []).append(f"{entry.key} = {toml_value(value)}")
    text = "".join(f"[{s}]\n" + "\n".join(lines) + "\n" for s, lines in sections.items())
    try:
        parse_config(text, "fuzz.toml")
    except ConfigError as exc:
        assert exc.problems and all(p.startswith("[") for p in exc.problems)
        # One problem per bad key at most (a table of entries: one per bad entry), plus cross-key
        # problems (one per section at most).
        allowed = sum(len(v) if isinstance(v, dict) and e.kind in ("names", "schedules") else 1 for e, v in entries)
        assert len(exc.problems) <= allowed + len(sections)
