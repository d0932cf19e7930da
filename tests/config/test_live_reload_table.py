"""The restart-only parts of the configuration: what differs is named, and is kept as it runs."""

from __future__ import annotations

from nfwserver.config import parse_config
from nfwserver.config.live_reload import RESTART_ONLY, keep_running, restart_needed

RUNNING = parse_config('[observer]\nlocation = "JO02ae"\n[tcp]\nenabled = true\nport = 8090\n'
                       '[radio]\nbackend = "rigctld"\nhost = "127.0.0.1"\nstep_hz = 10\n')


def test_live_values_need_no_restart_and_are_taken() -> None:
    new = parse_config('[observer]\nlocation = "JO62qm"\n[tcp]\nenabled = true\nport = 8090\n'
                       '[radio]\nbackend = "rigctld"\nhost = "127.0.0.1"\nstep_hz = 50\n')
    assert restart_needed(RUNNING, new) == []
    kept = keep_running(RUNNING, new)
    assert kept.observer == new.observer and kept.radio.step_hz == 50


def test_restart_only_values_are_named_and_kept_as_running() -> None:
    new = parse_config('[observer]\nlocation = "JO62qm"\n[tcp]\nenabled = true\nport = 8091\n'
                       '[radio]\nbackend = "rigctld"\nhost = "127.0.0.2"\nstep_hz = 50\n')
    assert restart_needed(RUNNING, new) == ["[radio] backend", "[tcp]"]
    kept = keep_running(RUNNING, new)
    assert kept.tcp.port == 8090 and kept.radio.host == "127.0.0.1"  # still what runs
    assert kept.radio.step_hz == 50 and kept.observer == new.observer  # the live parts are new
    assert restart_needed(RUNNING, kept) == []  # so the next comparison is true


def test_every_restart_only_path_exists_on_the_configuration() -> None:
    for _, paths in RESTART_ONLY:
        for path in paths:
            value: object = RUNNING
            for name in path.split("."):
                assert hasattr(value, name), path
                value = getattr(value, name)
