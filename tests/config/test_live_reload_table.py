"""The one table of the configuration's parts: live ones are applied, restart-only ones named and kept."""

from __future__ import annotations

from dataclasses import fields

from nfwserver.app.live_config import CONFIG_PARTS
from nfwserver.clock import VirtualClock
from nfwserver.config.live_reload import keep_running, restart_needed
from nfwserver.config.loader import parse_config
from nfwserver.core.station_core import StationCore
from nfwserver.tracking.catalog import Catalog
from tests.dde.conftest import CATALOG, ISS, ISS_PASS

RUNNING = parse_config('[observer]\nlocation = "JO02ae"\n[tcp]\nenabled = true\nport = 8090\n'
                       '[radio]\nbackend = "rigctld"\nhost = "127.0.0.1"\nstep_hz = 10\n')


def test_live_values_need_no_restart_and_are_taken() -> None:
    new = parse_config('[observer]\nlocation = "JO62qm"\n[tcp]\nenabled = true\nport = 8090\n'
                       '[radio]\nbackend = "rigctld"\nhost = "127.0.0.1"\nstep_hz = 10\nenabled = true\n')
    assert restart_needed(CONFIG_PARTS, RUNNING, new) == []
    kept = keep_running(CONFIG_PARTS, RUNNING, new)
    assert kept.observer == new.observer and kept.radio.enabled


def test_restart_only_values_are_named_and_kept_as_running() -> None:
    new = parse_config('[observer]\nlocation = "JO62qm"\n[tcp]\nenabled = true\nport = 8091\n'
                       '[radio]\nbackend = "rigctld"\nhost = "127.0.0.2"\nstep_hz = 50\n')
    # The radio's step and knob tolerance are the running tuner's: a reload names them rather than pretend.
    assert restart_needed(CONFIG_PARTS, RUNNING, new) == ["[radio] backend", "[radio] step_hz and knob_tolerance_hz",
                                                          "[tcp]"]
    kept = keep_running(CONFIG_PARTS, RUNNING, new)
    assert kept.tcp.port == 8090 and kept.radio.host == "127.0.0.1" and kept.radio.step_hz == 10  # what runs
    assert kept.observer == new.observer  # the live parts are new
    assert restart_needed(CONFIG_PARTS, RUNNING, kept) == []  # so the next comparison is true


def test_every_path_exists_on_the_configuration_and_belongs_to_one_part() -> None:
    paths = [path for part in CONFIG_PARTS for path in part.paths]
    assert len(paths) == len(set(paths))
    for path in paths:
        value: object = RUNNING
        for name in path.split("."):
            assert name in {f.name for f in fields(value)}, path  # type: ignore[arg-type]
            value = getattr(value, name)
    assert len({part.label for part in CONFIG_PARTS}) == len(CONFIG_PARTS)


def test_each_live_part_reaches_the_running_core_and_only_when_it_changed() -> None:
    catalog = Catalog(s.elements for s in CATALOG)
    core = StationCore(catalog, RUNNING.observer, VirtualClock(ISS_PASS.tca), satellite=ISS, rate_hz=5)
    new = parse_config('[observer]\nlocation = "JO62qm"\n[server]\nrate_hz = 2\nut1_utc_s = 0.25\n'
                       '[satellites]\nnames = { 25544 = "ARISS" }\n[radio]\nenabled = true\n'
                       '[web]\nhostnames = ["station.lan"]\n')  # the web server's part: the station hands it on
    live = [(part, part.apply) for part in CONFIG_PARTS if part.apply is not None]
    assert live and all(part.differs(RUNNING, new) for part, _ in live)
    for _, apply in live:
        apply(core, new)
    state = core.state
    assert state.observer == new.observer and state.rate_hz == 2 and state.ut1_utc_s == 0.25
    iss = state.catalog.get(ISS)
    assert iss is not None and iss.dde_name == "ARISS"
    assert core.snapshot().state.doppler_on
    assert not any(part.differs(new, new) for part in CONFIG_PARTS)
