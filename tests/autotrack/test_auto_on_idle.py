"""``AUTO ON`` takes effect at once or says why it will do nothing: with no satellites to work, or listed names
the catalog does not know, the reply says so (TCP ``OK warning: ...``), on every face, and autotrack is on
(it plans again when the list or the catalog changes).  Before, the reply was a plain ``OK`` and only a later
STATUS showed ``auto_problems``."""

from __future__ import annotations

import pytest

from nfwserver.app.autotrack_link import StationAutotrack
from nfwserver.clock import VirtualClock
from nfwserver.config.loader import parse_config
from nfwserver.core.station_core import StationCore
from nfwserver.dde.nova_service import NovaDdeService
from nfwserver.fake_dde import FakeDdeSystem
from nfwserver.tcp.protocol import NovaTcpProtocol
from nfwserver.tracking.catalog import Catalog
from nfwserver.tracking.elements import load_element_file
from tests.autotrack.test_runtime import START
from tests.autotrack.test_schedule_cli import AMATEUR

CATALOG = Catalog(load_element_file(AMATEUR).sets)


def _station(autotrack_section: str) -> tuple[StationCore, StationAutotrack]:
    config = parse_config('[observer]\nlocation = "JO02ae"\n[autotrack]\n' + autotrack_section)
    clock = VirtualClock(START)
    core = StationCore(CATALOG, config.observer, clock, rate_hz=1.0)
    autotrack = StationAutotrack(core, clock, lambda: config)
    autotrack.restore(None, None, None, "no state file")
    return core, autotrack


@pytest.mark.parametrize(("section", "said"), [
    ("satellites = []\n", "no satellites to work"),
    ('satellites = ["NO-SUCH-SAT", "99999"]\n', "NO-SUCH-SAT is not in the catalog; 99999 is not in the catalog"),
])
def test_auto_on_with_nothing_to_work_says_why(section: str, said: str) -> None:
    core, autotrack = _station(section)
    reply = NovaTcpProtocol(core).handle("AUTO ON", "tcp 127.0.0.1:1")
    assert reply is not None and len(reply.lines) == 1
    assert reply.lines[0].startswith("OK warning: autotrack is on but has nothing to work: ") and said in \
        reply.lines[0], reply.lines
    assert autotrack.runtime.on
    recorded = [e for e in core.events.recent() if e.kind == "poke"][-1]
    assert recorded.accepted and said in recorded.detail


def test_auto_on_with_an_unknown_name_among_known_ones_names_it_and_works_the_rest() -> None:
    core, autotrack = _station('satellites = ["NO-SUCH-SAT", "ISS"]\n')
    system = FakeDdeSystem()
    NovaDdeService(core).attach(system.server_transport())
    system.connect("NFW32", "NFW_DATA").poke("NFW_SERVER", "AUTO ON")  # acknowledged (a refusal raises)
    recorded = [e for e in core.events.recent() if e.kind == "poke"][-1]
    assert recorded.accepted and recorded.detail == "autotrack is on; left out: NO-SUCH-SAT is not in the catalog"
    assert autotrack.follow(START) == 25544


def test_auto_on_with_a_usable_list_is_a_plain_ok() -> None:
    core, _autotrack = _station('satellites = ["ISS", "SO-50"]\n')
    reply = NovaTcpProtocol(core).handle("AUTO ON", "tcp 127.0.0.1:1")
    assert reply is not None and reply.lines == ("OK",)
