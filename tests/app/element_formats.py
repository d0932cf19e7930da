"""Element files in the forms the named sources serve (CelesTrak TLE, OMM JSON and OMM CSV; AMSAT's bare TLE),
made from a TLE file of tests/data, for tests that serve them over a real local HTTP server."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

from bench.campaign.fuzz_elements import OMM_KEYS, omm_record
from nfwserver.tracking.elements import load_element_file


def omm_records(path: Path) -> list[dict]:
    """The sets of ``path`` as CelesTrak's OMM JSON records (``FORMAT=json``)."""
    return [omm_record(es) for es in load_element_file(path).sets]


def omm_json(path: Path) -> str:
    return json.dumps(omm_records(path))


def omm_csv(path: Path) -> str:
    """The sets of ``path`` as CelesTrak's OMM CSV (``FORMAT=csv``): a header row, then one row per set."""
    out = io.StringIO()
    writer = csv.DictWriter(out, fieldnames=OMM_KEYS, lineterminator="\r\n")
    writer.writeheader()
    writer.writerows(omm_records(path))
    return out.getvalue()


def bare_tle(path: Path) -> str:
    """AMSAT's nasabare.txt: name line, line 1, line 2, CR LF line ends."""
    return "".join(es.tle_text() for es in load_element_file(path).sets).replace("\n", "\r\n")
