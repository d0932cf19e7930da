"""A headless station started and stopped at once, as `nfwserver run --headless` would run it (its start-up
notes on stderr, its log in ``tmp_path``), on a virtual clock and the in-process DDE transport."""

from __future__ import annotations

import threading
from pathlib import Path

from nfwserver.cli.run_command import RunPlan, serve
from nfwserver.clock import VirtualClock
from nfwserver.config.schema import Config
from nfwserver.fake_dde import FakeDdeSystem
from tests.dde.conftest import ISS_PASS


def serve_once(config: Config, tmp_path: Path) -> int:
    """Run ``config``'s station headless until it has started, then stop it; returns the exit status."""
    stop = threading.Event()
    stop.set()
    plan = RunPlan(console=False, log_file=tmp_path / "nfw.log", clock=VirtualClock(ISS_PASS.aos),
                   transport=FakeDdeSystem().server_transport(), stop=stop)
    return serve(config, plan)
