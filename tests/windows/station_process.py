"""A real ``nfwserver run --headless`` in a process of its own (Windows side, under Wine or Windows).

The station is the one users run: configuration file, ``default_transport`` (DDEML), publisher.
It stops by itself after ``--duration``; :meth:`StationProcess.stop` ends it early (under Wine
that is TerminateProcess: no clean shutdown, used only when a test is over).
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from tests.waiting import wait_for

ROOT = Path(__file__).resolve().parent.parent.parent


class StationProcess:
    """``python -m nfwserver run --headless --config CONFIG --duration S`` with its log file."""

    def __init__(self, config: Path, duration_s: float, log_file: Path) -> None:
        self.log_file = log_file
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "nfwserver", "run", "--headless", "--config", str(config),
             "--log-file", str(log_file), "--duration", f"{duration_s:g}"],
            cwd=ROOT, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
        )

    def wait_serving(self, service: str = "NFW32", topic: str = "NFW_DATA", timeout_s: float = 60.0) -> None:
        """Return once a DDEML client can connect to ``service``/``topic``; raise if it never can."""
        from nfwserver.dde.ddeml_client import DdemlClient, DdeRefused

        client = DdemlClient()

        def serving() -> bool:
            if self.proc.poll() is not None:
                raise RuntimeError(f"the station exited with {self.proc.returncode}: {self.stderr()}")
            try:
                client.disconnect(client.connect(service, topic))
                return True
            except DdeRefused:
                client.pump(0.2)  # the wait between tries: DDE messages flow meanwhile
                return False

        try:
            wait_for(serving, timeout_s, f"the station to serve {service}/{topic}", interval_s=0.0)
        finally:
            client.close()

    def stderr(self) -> str:
        if self.proc.poll() is None or self.proc.stderr is None:
            return ""
        return self.proc.stderr.read().decode("utf-8", "replace")

    def stop(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(10)
