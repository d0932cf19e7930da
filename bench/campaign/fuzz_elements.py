"""Seeded generators of hostile element files: TLE text, AMSAT verbose sets, OMM JSON and OMM CSV.

Each file starts from real sets (tests/data/visual.txt) and is spoiled in ways a careless or hostile
source could: characters changed, lines cut, swapped or repeated, names with control characters,
markup and line breaks, non-finite and huge numbers, 5,000-digit JSON integers, 140,000-character CSV
fields, epochs in 9999, truncated documents, deep nesting, random bytes.  ``ElementFuzzer(seed)`` gives
the same files for the same seed.
"""

from __future__ import annotations

import json
import random
from pathlib import Path

from nfwserver.tracking.elements import ElementSet, load_element_file

ROOT = Path(__file__).resolve().parent.parent.parent
SOURCE_SETS = ROOT / "tests" / "data" / "visual.txt"

HOSTILE_NAMES = ("X [/bold] Y", "[bold red]PWNED[/]", "\x1b[31mRED\x1b[0m", "A\nB", "A\rB", "tab\there", "\x00NUL",
                 "1 25544U", "2 25544", "0 ", "Satellite: fake", "NORAD_CAT_ID,MEAN_MOTION", "\u202eevil", "名字",
                 "x" * 300, "%s%s%n", "'; DROP TABLE", "\ufeffBOM", " ", "")
HOSTILE_NUMBERS = (float("inf"), float("-inf"), float("nan"), "1e999", "-1e999", 1e308, -0.0, 0, -1, 1.5, 1e-12,
                   "", None, [], {}, True, "abc", "0x10", "1_000", " 7 ", 10**20, "__BIGINT__", "__LONGTEXT__")
HOSTILE_EPOCHS = ("9999-01-01T00:00:00", "1956-12-31T23:59:59", "2024-02-30T00:00:00", "garbage", "", "2024-01-01",
                  "2024-01-01T00:00:00+05:00", "2024-01-01T00:00:00Z", "-0001-01-01T00:00:00", "2056-12-31T23:59:59")
OMM_KEYS = ("OBJECT_NAME", "OBJECT_ID", "EPOCH", "MEAN_MOTION", "ECCENTRICITY", "INCLINATION", "RA_OF_ASC_NODE",
            "ARG_OF_PERICENTER", "MEAN_ANOMALY", "EPHEMERIS_TYPE", "CLASSIFICATION_TYPE", "NORAD_CAT_ID",
            "ELEMENT_SET_NO", "REV_AT_EPOCH", "BSTAR", "MEAN_MOTION_DOT", "MEAN_MOTION_DDOT")
AMSAT = ("Satellite: {name}\nCatalog number: {catnr}\nEpoch time:      {epoch}\nElement set:     {setno}\n"
         "Inclination:       {incl} deg\nRA of node:       {raan} deg\nEccentricity:    {ecc}\n"
         "Arg of perigee:   {argp} deg\nMean anomaly:       {ma} deg\nMean motion:    {mm} rev/day\n"
         "Decay rate:        {decay} rev/day^2\nEpoch rev:            {rev}\nChecksum:              0\n\n")


def _designator(es: ElementSet) -> str:
    d = es.international_designator
    if len(d) < 5 or not d[:2].isdigit():
        return d
    year = int(d[:2])
    return f"{1900 + year if year >= 57 else 2000 + year}-{d[2:]}"


def omm_record(es: ElementSet) -> dict:
    """The set as a CelesTrak OMM record."""
    return {"OBJECT_NAME": es.name, "OBJECT_ID": _designator(es),
            "EPOCH": es.epoch.replace(tzinfo=None).isoformat(timespec="microseconds"),
            "MEAN_MOTION": es.mean_motion_rev_per_day, "ECCENTRICITY": es.eccentricity,
            "INCLINATION": es.inclination_deg, "RA_OF_ASC_NODE": es.raan_deg,
            "ARG_OF_PERICENTER": es.arg_perigee_deg, "MEAN_ANOMALY": es.mean_anomaly_deg, "EPHEMERIS_TYPE": 0,
            "CLASSIFICATION_TYPE": "U", "NORAD_CAT_ID": es.catalog_number, "ELEMENT_SET_NO": 999,
            "REV_AT_EPOCH": es.rev_number, "BSTAR": es.bstar, "MEAN_MOTION_DOT": float(es.line1[33:43]),
            "MEAN_MOTION_DDOT": 0.0}


class ElementFuzzer:
    """``next_file()`` -> (format name, file content as str or bytes)."""

    FORMATS = ("tle", "amsat", "omm-json", "omm-csv", "mixed", "bytes")

    def __init__(self, seed: int) -> None:
        self.rng = random.Random(seed)
        self.sets = load_element_file(SOURCE_SETS).sets

    # -- pieces ----------------------------------------------------------------------------------------
    def _sample(self) -> list[ElementSet]:
        return self.rng.sample(self.sets, self.rng.randint(1, 6))

    def _name(self, es: ElementSet) -> str:
        return self.rng.choice(HOSTILE_NAMES) if self.rng.random() < 0.3 else es.name

    def _spoil_line(self, line: str) -> str:
        rng = self.rng
        kind = rng.random()
        if not line or kind < 0.4:
            j = rng.randrange(max(1, len(line)))
            return line[:j] + rng.choice("0123456789 -+.eExZ\x00\x1b\t") + line[j + 1:]
        if kind < 0.6:
            return line[: rng.randrange(max(1, len(line)))]
        if kind < 0.7:
            return line + rng.choice(("", " junk", "9" * 80, "\x7f"))
        if kind < 0.75:
            return line * rng.randint(2, 50)
        if kind < 0.8:
            return "".join(rng.sample(line, len(line)))
        return line.replace(rng.choice(line), rng.choice("9 -."))

    def _value(self, original: object) -> object:
        return self.rng.choice(HOSTILE_NUMBERS) if self.rng.random() < 0.85 else original

    def _finish_json(self, text: str) -> str:
        text = text.replace('"__BIGINT__"', "9" * self.rng.choice((31, 4301, 5000)))
        text = text.replace("__LONGTEXT__", "7" * self.rng.choice((5000, 140_000)))
        if self.rng.random() < 0.1:
            text = text[: self.rng.randrange(max(1, len(text)))]
        return text

    # -- formats -----------------------------------------------------------------------------------------
    def tle(self) -> str:
        lines: list[str] = []
        for es in self._sample():
            block = [self._name(es), es.line1, es.line2]
            if self.rng.random() < 0.5:
                i = self.rng.randrange(3)
                block[i] = self._spoil_line(block[i])
            if self.rng.random() < 0.1:
                block.reverse()
            if self.rng.random() < 0.1:
                block = block[1:]  # the two-line form
            lines += block
            if self.rng.random() < 0.15:
                lines.append(self.rng.choice(("", "junk", "1 ", "2 x", "{", "[group]", "\x00\x01", "0 NAME")))
        return self.rng.choice(("\n", "\r\n", "\r")).join(lines)

    def amsat(self) -> str:
        out = []
        for es in self._sample():
            day = es.epoch.timetuple().tm_yday + (es.epoch.hour * 3600 + es.epoch.minute * 60 + es.epoch.second) / 86400
            values = dict(name=self._name(es), catnr=es.catalog_number, epoch=f"{es.epoch.year % 100:02d}{day:012.8f}",
                          setno=999, incl=es.inclination_deg, raan=es.raan_deg, ecc=es.eccentricity,
                          argp=es.arg_perigee_deg, ma=es.mean_anomaly_deg, mm=es.mean_motion_rev_per_day,
                          decay=float(es.line1[33:43]), rev=es.rev_number)
            for key in self.rng.sample(sorted(values), self.rng.randint(0, 3)):
                values[key] = self._value(values[key])
            text = AMSAT.format(**values).replace("__BIGINT__", "9" * 5000).replace("__LONGTEXT__", "7" * 140_000)
            if self.rng.random() < 0.2:
                lines = text.splitlines()
                del lines[self.rng.randrange(len(lines))]
                text = "\n".join(lines) + "\n"
            out.append(text)
        return "".join(out)

    def _records(self) -> list[dict]:
        records = []
        for es in self._sample():
            record = omm_record(es)
            record["OBJECT_NAME"] = self._name(es)
            for key in self.rng.sample(OMM_KEYS, self.rng.randint(0, 3)):
                if self.rng.random() < 0.15:
                    record.pop(key)
                elif key == "EPOCH":
                    record[key] = self.rng.choice(HOSTILE_EPOCHS)
                else:
                    record[key] = self._value(record[key])
            records.append(record)
        return records

    def omm_json(self) -> str:
        records = self._records()
        pick = self.rng.random()
        if pick < 0.05:
            return "[" * self.rng.choice((10, 5000, 100_000))
        if pick < 0.1:
            return json.dumps(records[0])  # one object, not a list
        if pick < 0.15:
            return json.dumps([records, 1, "x", None])
        return self._finish_json(json.dumps(records))

    def omm_csv(self) -> str:
        records = self._records()
        header = list(OMM_KEYS)
        if self.rng.random() < 0.2:
            self.rng.shuffle(header)
        rows = [",".join(header)]
        for record in records:
            cells = []
            for key in header:
                value = record.get(key, "")
                text = "" if value is None else str(value)
                if self.rng.random() < 0.05:
                    text = '"' + text.replace('"', '""') + ',"'
                cells.append(text)
            row = ",".join(cells)
            if self.rng.random() < 0.1:
                row = self._spoil_line(row)
            rows.append(row)
        text = "\n".join(rows) + "\n"
        return self._finish_json(text).replace("\ufeff", "")

    def mixed(self) -> str:
        parts = [self.tle(), self.amsat(), self.omm_csv()]
        self.rng.shuffle(parts)
        return "\n".join(parts[: self.rng.randint(1, 3)])

    def random_bytes(self) -> bytes:
        return bytes(self.rng.getrandbits(8) for _ in range(self.rng.randint(0, 4000)))

    def next_file(self) -> tuple[str, str | bytes]:
        kind = self.rng.choice(self.FORMATS)
        make = {"tle": self.tle, "amsat": self.amsat, "omm-json": self.omm_json, "omm-csv": self.omm_csv,
                "mixed": self.mixed, "bytes": self.random_bytes}[kind]
        return kind, make()
