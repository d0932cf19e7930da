"""The one table drives everything: the records' defaults, the template and `config show` cover every key."""

from __future__ import annotations

import re
from dataclasses import fields, replace

import pytest

from nfwserver.cli import main
from nfwserver.config.loader import parse_config
from nfwserver.config.render import show, template
from nfwserver.config.schema import (
    Config,
    DialectsConfig,
    EasyCommConfig,
    ElementsConfig,
    RadioConfig,
    RotorConfig,
    ServerConfig,
    TcpConfig,
)
from nfwserver.config.table import SECTION_NAMES, SETTINGS, default, keys_of

RECORDS = {"elements": ElementsConfig, "server": ServerConfig, "radio": RadioConfig, "rotor": RotorConfig,
           "dialects": DialectsConfig, "tcp": TcpConfig, "easycomm": EasyCommConfig}


def _by_section(text: str) -> dict[str, str]:
    """Text of each ``[section]`` block of a TOML-like document."""
    parts = re.split(r"^\[([a-z]+)\]$", text, flags=re.MULTILINE)
    return {parts[i]: parts[i + 1] for i in range(1, len(parts), 2)}


def test_every_key_is_in_the_template_under_its_section() -> None:
    blocks = _by_section(template())
    assert list(blocks) == list(SECTION_NAMES)
    for entry in SETTINGS:
        block = blocks[entry.section]
        if entry.kind == "channels":
            assert "# [[satellites.channels]]" in block
            continue
        written = re.search(rf"^(# )?{entry.key} = ", block, flags=re.MULTILINE)
        assert written, f"{entry.name} missing from the template"
        assert entry.help.split()[0] in block  # its help text is the comment above it
        # Keys with a default are written live; keys that are not set by default are examples.
        assert (written.group(1) is None) == (entry.default is not None and entry.example is None), entry.name


def test_template_parses_back_to_exactly_the_defaults() -> None:
    """Except the starting choices (the named element source), which the template says it sets."""
    config = parse_config(template())
    assert config.elements.sources == ("amateur",)
    assert "(a starting choice; without this line: sources = [])" in template()
    assert replace(config, source=Config().source, elements=Config().elements) == Config()
    assert replace(config.elements, sources=()) == Config().elements


def test_every_key_is_in_config_show(tmp_path, capsys) -> None:
    path = tmp_path / "config.toml"
    path.write_text(template())
    assert main(["config", "show", "--config", str(path)]) == 0
    blocks = _by_section(capsys.readouterr().out)
    assert list(blocks) == list(SECTION_NAMES)
    for entry in SETTINGS:
        assert re.search(rf"^{entry.key} = ", blocks[entry.section], flags=re.MULTILINE), entry.name


@pytest.mark.parametrize("section", RECORDS)
def test_record_fields_are_exactly_the_table_keys_with_the_table_defaults(section) -> None:
    record = RECORDS[section]
    table_fields = {e.where.split(".", 1)[1]: e for e in SETTINGS if e.where.startswith(f"{section}.")}
    assert {f.name for f in fields(record)} == set(table_fields)
    instance = record()
    for name, entry in table_fields.items():
        assert getattr(instance, name) == default(entry.section, entry.key), entry.name


def test_table_entries_are_complete() -> None:
    assert len({(e.section, e.key) for e in SETTINGS}) == len(SETTINGS)
    for entry in SETTINGS:
        assert entry.section in SECTION_NAMES and entry.help, entry.name
        if entry.kind in ("number", "int"):
            assert entry.lo is not None and entry.hi is not None, entry.name
        if entry.kind in ("choice", "choices"):
            assert entry.choices, entry.name
    assert keys_of("tcp") == ("enabled", "host", "port", "allow", "max_clients", "max_per_address", "idle_timeout_s")
    assert keys_of("easycomm") == ("enabled", "device", "baud", "rate_hz", "uplink")


def test_show_prints_the_effective_values(tmp_path, capsys) -> None:
    (tmp_path / "h.txt").write_text("0 5\n180 10\n")
    path = tmp_path / "config.toml"
    path.write_text('[observer]\nlocation = "52.2,0.12,20"\n[horizon]\nfile = "h.txt"\n'
                    '[elements]\nstore = "cat.txt"\n[tcp]\nenabled = true\nport = 9000\nallow = ["10.0.0.0/8"]\n'
                    '[easycomm]\nenabled = true\ndevice = "/dev/ttyUSB1"\nbaud = 19200\nuplink = "doppler"\n'
                    '[[satellites.channels]]\ncatalog_number = 99999\nname = "TEST"\ndownlink_hz = 435000000\n')
    assert main(["config", "show", "--config", str(path)]) == 0
    blocks = _by_section(capsys.readouterr().out)
    assert 'location = "52.2,0.12,20"' in blocks["observer"]
    assert "latitude_deg = 52.2  # from location\n" in blocks["observer"]
    assert "points = [[0, 5], [180, 10]]" in blocks["horizon"]
    assert f'file = "{tmp_path / "h.txt"}"' in blocks["horizon"]
    assert f'store = "{tmp_path / "cat.txt"}"' in blocks["elements"]
    assert "enabled = true\n" in blocks["tcp"] and "port = 9000\n" in blocks["tcp"]
    assert 'allow = ["10.0.0.0/8"]' in blocks["tcp"]
    assert 'device = "/dev/ttyUSB1"' in blocks["easycomm"] and "baud = 19200" in blocks["easycomm"]
    assert 'uplink = "doppler"' in blocks["easycomm"]
    assert "channels = 6 channels" in blocks["satellites"] and "99999: TEST: down 435000000 Hz FM" in \
        blocks["satellites"]


def test_show_resolves_the_default_store(capsys, tmp_path) -> None:
    path = tmp_path / "config.toml"
    path.write_text("")
    assert main(["config", "show", "--config", str(path)]) == 0
    out = capsys.readouterr().out
    from nfwserver.app.element_store import default_store_path

    assert f'store = "default"  # default: {default_store_path()}' in out
    assert "device = (not set)" in out and "location = (not set)  # not set: using" in out


def test_show_carries_the_warnings() -> None:
    config = parse_config('[tcp]\nenabled = true\nhost = "0.0.0.0"\n')
    assert show(config).splitlines()[1].startswith("# warning: [tcp] host")
