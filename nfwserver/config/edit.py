"""Changing one key of the configuration file, keeping the user's comments and layout (``config set``).

The file is edited as a TOML document with ``tomlkit`` (comments, blank lines and key order survive),
the result is validated as a whole by the configuration table (:func:`parse_config`, and each entry's
further check: a weak ``[web] token`` is refused here, though a file holding one still loads) before anything is
written, and it is written atomically (:func:`nfwserver.storage.atomic_write_text`, which keeps the
file's permissions): a refused value leaves the file as it was.
"""

from __future__ import annotations

import difflib
import re
from pathlib import Path
from typing import Any

import tomlkit
from tomlkit.exceptions import TOMLKitError
from tomlkit.items import AoT, InlineTable, Table

from nfwserver.config.loader import ConfigError, TomlError, failed_checks, parse_config, toml_document
from nfwserver.config.table import SECTIONS, keys_of
from nfwserver.config.tokens import new_token

__all__ = ["TEXT_KINDS", "parse_value", "set_key", "split_key"]

#: Kinds of setting whose value is text: a value that TOML would read as a number or a boolean (a token of
#: digits, a device named 1) is taken as the text typed.
TEXT_KINDS = frozenset({"text", "host", "url", "file", "store", "location", "device"})


def split_key(name: str) -> tuple[str, str]:
    """``"observer.location"`` as (section, key); raises ValueError naming the closest known key."""
    section, dot, key = name.partition(".")
    known = [f"{s.name}.{k}" for s in SECTIONS for k in keys_of(s.name)]
    if not dot or name not in known:
        close = difflib.get_close_matches(name, known, n=1)
        hint = f" (did you mean {close[0]}?)" if close else " (`nfwserver config show` lists them)"
        raise ValueError(f"no setting {name!r}{hint}")
    return section, key


def parse_value(text: str, kind: str | None = None) -> Any:
    """The value ``text`` stands for: a TOML value when it is one (``true``, ``12.5``, ``[25544, 7530]``,
    ``"quoted"``), else the text itself as a string (``JO01ab``, ``/dev/ttyUSB0``).  For a setting of a text
    ``kind`` (:data:`TEXT_KINDS`), a number or boolean is the text as typed (``12345678`` as a token)."""
    try:
        value = toml_document(f"v = {text}")["v"]
    except TomlError:
        return text
    if kind in TEXT_KINDS and not isinstance(value, (str, list, dict)):
        return text
    return value


def set_key(text: str, section: str, key: str, value: Any, source: str, base_dir: Path) -> str:
    """``text`` (a configuration file's content) with ``[section] key = value``; raises
    :class:`ConfigError` when the result is not a valid configuration (the problem named)."""
    try:
        toml_document(text)  # the reader the station uses: its one sentence for a file that is not TOML
        doc = tomlkit.parse(text.removeprefix("\ufeff"))  # a BOM, as toml_document skips it
    except (TomlError, TOMLKitError) as exc:
        raise ConfigError(source, [f"the file is not valid TOML, so it was not changed ({_sentence(exc)})"]) from None
    table = doc.get(section)
    if table is None:
        table = tomlkit.table()
        doc.add(section, table)
    elif not isinstance(table, (Table, InlineTable)):
        what = f"an array of tables ([[{section}]])" if isinstance(table, AoT) else f"a plain value ({section} = ...)"
        raise ConfigError(source, [f"[{section}] is {what} in the file, not a table; fix or remove it first"])
    table[key] = value
    new = tomlkit.dumps(doc)
    new = _drop_commented_example(new, section, key)
    config = parse_config(new, source, base_dir)  # raises ConfigError with every problem
    failed = failed_checks(config)  # a weak token: a file may be loaded with one, but is never written with one
    if failed:
        raise ConfigError(source, [f"{entry.name}: {why}" + (f" (for a fresh one: nfwserver config set web.token "
                                                             f"{new_token()})" if entry.key == "token" else "")
                                   for entry, why in failed])
    return new


def _sentence(exc: Exception) -> str:
    """An exception's message as one line (TOML readers' messages hold the line and column)."""
    return " ".join(str(exc).split()) or type(exc).__name__


def _drop_commented_example(text: str, section: str, key: str) -> str:
    """Remove ``# key = ...`` lines of ``[section]`` (``config init``'s commented examples) now that the key
    is set, so the file does not show two values for it."""
    lines = text.splitlines(keepends=True)
    current = None
    pattern = re.compile(rf"#\s*{re.escape(key)}\s*=")
    out = []
    for line in lines:
        header = re.match(r"\s*\[([^\]]+)\]", line)
        if header:
            current = header.group(1).strip()
        if current == section and pattern.match(line.strip()):
            continue
        out.append(line)
    return "".join(out)

