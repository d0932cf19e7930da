"""Seeded generators of hostile configurations, Nova pokes / TCP lines and PREDICT datagrams.

Each generator starts from what a real client sends (the configuration table's keys, Nova's poke
grammar, PREDICT's command words) and spoils it: hostile values, case and blank games, control
characters, CR/LF/NUL inside a line, over-long text, random bytes.
"""

from __future__ import annotations

import os
import random
import time
from pathlib import Path

from nfwserver.config.render import toml_value
from nfwserver.config.table import SETTINGS

_SCALARS = (True, False, 0, -1, 1, 50, 1210, 65535, 65536, 10**12, -10**12, 0.5, -0.0, 1e308, float("inf"),
            float("-inf"), float("nan"), "", " ", "127.0.0.1", "0.0.0.0", "::1", "10.0.0.0/8", "999.1.1.1/99",
            "/dev/zero", "/dev/null", "/nonexistent/x", "auto", "on", "off", "doppler", "JO02ae", "ZZ99zz",
            "52.2,0.12,20", "none", "default", "rotctld", "rigctld", "sim", "overlap-450", "x" * 5000,
            "\x1b[31m", "[/b]", "a\nb", "名字", "http://127.0.0.1:1/x", "file:///etc/passwd", "ftp://x", "25544",
            "N0CALL")


def _value(rng: random.Random, fifo: str | None) -> object:
    pick = rng.random()
    if pick < 0.55:
        return rng.choice(_SCALARS + ((fifo,) if fifo else ()))
    if pick < 0.7:
        return rng.uniform(-1e6, 1e6)
    if pick < 0.85:
        return [rng.choice(_SCALARS) for _ in range(rng.randint(0, 4))]
    if pick < 0.95:
        return [[rng.choice((0, 90, 180, 360, -5, 450.5, "x")) for _ in range(rng.randint(0, 3))]
                for _ in range(rng.randint(0, 4))]
    return {rng.choice(("25544", "x", "", "7530", "-1")): rng.choice(_SCALARS) for _ in range(rng.randint(0, 3))}


class ConfigFuzzer:
    """``next_text()`` -> a TOML document: keys from the whole table, hostile values, sometimes spoiled text.
    ``fifo`` names a FIFO that configuration files may point at (it must never block the reader)."""

    def __init__(self, seed: int, fifo: str | None = None) -> None:
        self.rng = random.Random(seed)
        self.fifo = fifo

    def next_text(self) -> str:
        rng = self.rng
        if rng.random() < 0.05:
            return "".join(chr(rng.randint(0, 0x2FF)) for _ in range(rng.randint(0, 300)))
        sections: dict[str, list[str]] = {}
        for entry in rng.sample(SETTINGS, rng.randint(1, 8)):
            sane = entry.example if entry.example is not None else entry.default
            value = sane if sane is not None and rng.random() < 0.6 else _value(rng, self.fifo)
            sections.setdefault(entry.section, []).append(f"{entry.key} = {toml_value(value)}")
        if rng.random() < 0.1:
            sections.setdefault(rng.choice(("junk", "server", "tcp")), []).append(f"unknown_key = {rng.randint(0, 9)}")
        text = "".join(f"[{section}]\n" + "\n".join(lines) + "\n" for section, lines in sections.items())
        if rng.random() < 0.1:
            j = rng.randrange(max(1, len(text)))
            text = text[:j] + rng.choice(("", "\x00", "[", "=", '"', "\n[server]\n", "\\u0000")) + text[j:]
        return text


POKE_WORDS = ("TUNE ON", "TUNE OFF", "TRACK ON", "TRACK OFF", "SAT=", "ANTAZ=", "ANTEL=", "tune on", " TUNE  ON ",
              "TUNE", "SAT", "=", "ANTAZ", "SAT==1", "TUNE ON TUNE OFF")
POKE_VALUES = ("25544", "27607", "7530", "0", "-0", "1", "99999", "999999999999999999999", "nan", "inf", "-inf",
               "1e309", "-1e309", "360", "359.99", "-90", "90", "91", "0x10", "1_000", " 12 ", "１２", "", "12a",
               "1.5e2", "--1")
CONTROL = ("\r", "\n", "\r\n", "\x00", "\t", "\x1b[2J", "\x7f", "\u2028", "\ufeff")


class PokeFuzzer:
    """``next_poke()`` -> text or bytes a DDE client pokes; ``next_line()`` -> bytes a TCP client sends
    (without its terminator; it may hold CR, LF or NUL, which end lines on the TCP side)."""

    def __init__(self, seed: int) -> None:
        self.rng = random.Random(seed)

    def _text(self) -> str:
        rng = self.rng
        word = rng.choice(POKE_WORDS)
        text = word + (rng.choice(POKE_VALUES) if word.endswith("=") else "")
        pick = rng.random()
        if pick < 0.15:
            j = rng.randrange(len(text) + 1)
            text = text[:j] + rng.choice(CONTROL) + text[j:]
        elif pick < 0.25:
            text = "".join(c.lower() if rng.random() < 0.5 else c for c in text)
        elif pick < 0.3:
            text = text * rng.randint(2, 2000)
        elif pick < 0.35:
            text = "".join(chr(rng.randint(1, 0xFFFF)) for _ in range(rng.randint(0, 60)))
        elif pick < 0.37:
            text = "A" * rng.choice((1023, 1024, 1025, 70_000))
        return text

    def next_poke(self) -> str | bytes:
        if self.rng.random() < 0.1:
            return bytes(self.rng.getrandbits(8) for _ in range(self.rng.randint(0, 200)))
        return self._text()

    def next_line(self) -> bytes:
        if self.rng.random() < 0.1:
            return bytes(self.rng.getrandbits(8) for _ in range(self.rng.randint(0, 200))).replace(b"\r", b"")
        if self.rng.random() < 0.05:
            return self.rng.choice((b"SUMMARY", b"STATUS", b" status ", b"Summary"))
        return self._text().encode("utf-8", errors="replace")


PREDICT_WORDS = ("GET_SAT", "GET_TLE", "GET_DOPPLER", "GET_LIST", "RELOAD_TLE", "GET_SUN", "GET_MOON", "GET_MODE",
                 "GET_VERSION", "GET_QTH", "GET_TIME$", "GET_TIME", "GET_SAT_POS", "PREDICT", "get_sat", "GET_SATX",
                 "", "Huh?")
PREDICT_NAMES = ("ISS (ZARYA)", "ISS", "25544", "27607", "7530", "NOAA 19", "-1", "0", "99999999999999999999",
                 "nan", "\x00", "A" * 70, "ISS (ZARYA)\nGET_SAT ISS", "\x1b[31m", "名字")


class DatagramFuzzer:
    """``next_datagram()`` -> bytes of one UDP request to the PREDICT server."""

    def __init__(self, seed: int) -> None:
        self.rng = random.Random(seed)

    def next_datagram(self) -> bytes:
        rng = self.rng
        pick = rng.random()
        if pick < 0.1:
            return bytes(rng.getrandbits(8) for _ in range(rng.randint(0, 3000)))
        word = rng.choice(PREDICT_WORDS)
        arg = rng.choice(PREDICT_NAMES)
        if word in ("GET_SAT_POS", "PREDICT"):
            now = int(time.time())
            start = rng.choice((now, now - 60, 0, -1, 2**63, now + 86400))
            end = start + rng.choice((0, 1, 30, -5))
            arg = f"{arg if ' ' not in arg else '25544'} {start}" + (f" {end}" if rng.random() < 0.7 else "")
        text = f"{word} {arg}" if rng.random() < 0.8 else word
        if rng.random() < 0.15:
            j = rng.randrange(len(text) + 1)
            text = text[:j] + rng.choice(CONTROL) + text[j:]
        return text.encode("utf-8", errors="replace")


def make_fifo(directory: Path) -> str | None:
    """A FIFO in ``directory`` that nothing writes to (None where FIFOs do not exist)."""
    path = directory / "fifo"
    try:
        os.mkfifo(path)
    except (AttributeError, OSError):
        return None
    return str(path)
