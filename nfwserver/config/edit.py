"""Changing one key of the configuration file, keeping the user's comments and layout (``config set``).

The file is edited as a TOML document with ``tomlkit`` (comments, blank lines and key order survive),
the result is validated as a whole by the configuration table (:func:`parse_config`) before anything is
written, and it is written atomically (:func:`nfwserver.storage.atomic_write_text`, which keeps the
file's permissions): a refused value leaves the file as it was.
"""

from __future__ import annotations

import difflib
import re
from pathlib import Path
from typing import Any

import tomlkit

from nfwserver.config.loader import TomlError, parse_config, toml_document
from nfwserver.config.table import SECTIONS, keys_of

__all__ = ["parse_value", "set_key", "split_key"]


def split_key(name: str) -> tuple[str, str]:
    """``"observer.location"`` as (section, key); raises ValueError naming the closest known key."""
    section, dot, key = name.partition(".")
    known = [f"{s.name}.{k}" for s in SECTIONS for k in keys_of(s.name)]
    if not dot or name not in known:
        close = difflib.get_close_matches(name, known, n=1)
        hint = f" (did you mean {close[0]}?)" if close else " (`nfwserver config show` lists them)"
        raise ValueError(f"no setting {name!r}{hint}")
    return section, key


def parse_value(text: str) -> Any:
    """The value ``text`` stands for: a TOML value when it is one (``true``, ``12.5``, ``[25544, 7530]``,
    ``"quoted"``), else the text itself as a string (``JO01ab``, ``/dev/ttyUSB0``)."""
    try:
        return toml_document(f"v = {text}")["v"]
    except TomlError:
        return text


def set_key(text: str, section: str, key: str, value: Any, source: str, base_dir: Path) -> str:
    """``text`` (a configuration file's content) with ``[section] key = value``; raises
    :class:`ConfigError` when the result is not a valid configuration (the problem named)."""
    doc = tomlkit.parse(text.removeprefix("\ufeff"))  # a BOM, as toml_document skips it
    table = doc.get(section)
    if table is None:
        table = tomlkit.table()
        doc.add(section, table)
    table[key] = value
    new = tomlkit.dumps(doc)
    new = _drop_commented_example(new, section, key)
    parse_config(new, source, base_dir)  # raises ConfigError with every problem
    return new


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

