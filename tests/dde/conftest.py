"""A station core with Nova's DDE service on the in-process transport under a virtual clock, near a real ISS pass."""

from __future__ import annotations

import re
from dataclasses import dataclass
from datetime import datetime, timedelta, timezone

import pytest

from nfwserver.clock import VirtualClock
from nfwserver.core.publisher import run_virtual
from nfwserver.core.state import StationState
from nfwserver.core.station_core import StationCore
from nfwserver.dde.nova_service import NovaDdeService
from nfwserver.fake_dde import FakeDdeSystem
from nfwserver.tracking.catalog import Catalog
from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.horizon import HorizonTable
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.passes import find_passes
from tests.conftest import DATA

ISS = 25544
#: Nova's string as the spec describes it (name, AZ one decimal, EL signed, RR ten decimals, AH Y/N).
NOVA = re.compile(r"^(\S{1,12}) AZ:(\d{1,3}\.\d) EL:(-?\d{1,2}\.\d) RR:(-?\d+\.\d{10}) AH:([YN])$")
OBSERVER = Observer(52.2053, 0.1218, 20.0)
CATALOG = Catalog(load_element_file(DATA / "visual.txt").sets)
DAY = datetime(2026, 5, 8, tzinfo=timezone.utc)
ISS_PASS = max(find_passes([CATALOG.get(ISS)], OBSERVER, DAY, DAY + timedelta(days=1)),
               key=lambda p: p.max_elevation_deg)


@dataclass
class Station:
    core: StationCore
    nova: NovaDdeService
    system: FakeDdeSystem
    clock: VirtualClock

    def run(self, seconds: float, before_tick=None) -> int:
        return run_virtual(self.core, self.clock, seconds, before_tick)


def make_station(start: datetime | None = None, rate_hz: float = 5.0, horizon: HorizonTable | None = None,
                 satellite: int | None = ISS, ut1_utc: float = 0.0, channels=None,
                 catalog: Catalog = CATALOG) -> Station:
    clock = VirtualClock(start or ISS_PASS.aos - timedelta(seconds=60))
    core = StationCore(catalog, OBSERVER, clock, horizon=horizon, rate_hz=rate_hz, satellite=satellite,
                       ut1_utc=ut1_utc, channels=channels)
    system = FakeDdeSystem()
    nova = NovaDdeService(core)
    nova.attach(system.server_transport())
    return Station(core, nova, system, clock)


def state_for(catalog_number: int, observer: Observer = OBSERVER) -> StationState:
    """A live station state at ``observer`` with ``catalog_number`` selected (for pass tracks)."""
    state = StationState(CATALOG, observer)
    state.select(catalog_number)
    return state


@pytest.fixture
def station() -> Station:
    return make_station()


def dead_iss_text(number: int = 99901) -> str:
    """ISS's element set under another number, dated ten years earlier: SGP4 reports it decayed now."""
    from nfwserver.tracking.tle import tle_checksum

    iss = CATALOG.get(ISS)
    assert iss is not None
    l1 = iss.elements.line1[:2] + f"{number:05d}" + iss.elements.line1[7:18] + "16" + iss.elements.line1[20:68]
    l2 = iss.elements.line2[:2] + f"{number:05d}" + iss.elements.line2[7:68]
    return f"DEAD\n{l1}{tle_checksum(l1)}\n{l2}{tle_checksum(l2)}\n"
