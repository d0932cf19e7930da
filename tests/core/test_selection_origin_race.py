"""Who chose the satellite is read with the satellite (issue 36 item 8): STATUS never pairs one satellite with
the face that chose another, while faces on their own threads keep choosing."""

from __future__ import annotations

import threading

from nfwserver.tcp.protocol import NovaTcpProtocol
from nfwserver.tcp.status_line import parse_status
from tests.dde.conftest import make_station


def test_status_pairs_each_satellite_with_its_chooser() -> None:
    station = make_station()
    core = station.core
    chooser = {25544: "face-a", 694: "face-b"}
    core.select_satellite(694, source="face-b")  # from the start, every selection is one of the two faces'
    stop = threading.Event()

    def choose(number: int) -> None:
        while not stop.is_set():
            core.select_satellite(number, source=chooser[number])

    threads = [threading.Thread(target=choose, args=(n,), daemon=True) for n in chooser]
    for thread in threads:
        thread.start()
    protocol = NovaTcpProtocol(core)
    try:
        pairs = set()
        for _ in range(10000):
            fields = parse_status(protocol.status_line())
            pairs.add((fields["satellite"], fields["satellite_from"]))
    finally:
        stop.set()
        for thread in threads:
            thread.join()
    assert pairs <= {("25544", "face-a"), ("694", "face-b")}, pairs
