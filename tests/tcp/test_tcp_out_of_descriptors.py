"""Out of file descriptors (issue 23 item 9): the accept loop rests instead of spinning, says so once,
and serves again when descriptors are free.

The server runs in a child process whose descriptor limit is lowered (``RLIMIT_NOFILE``), on the real
clock: its back-off is real time, and what is measured is the child's CPU time while clients queue up
that it cannot accept (before the fix the loop spun at 100 % of a core).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import textwrap
import time
from pathlib import Path

from tests.tcp.conftest import LineClient
from tests.waiting import wait_for

ROOT = Path(__file__).resolve().parents[2]
CHILD = textwrap.dedent("""
    import logging, resource, sys, time
    from nfwserver.clock import SystemClock
    from nfwserver.config.schema import TcpConfig
    from nfwserver.core.station_core import StationCore
    from nfwserver.tcp.server import NovaTcpServer
    from tests.dde.conftest import CATALOG, OBSERVER
    logging.basicConfig(level=logging.WARNING, stream=sys.stderr)
    core = StationCore(CATALOG, OBSERVER, SystemClock())
    server = NovaTcpServer(core, TcpConfig(enabled=True, host="127.0.0.1", port=0, allow=("127.0.0.1",),
                                           max_per_address=1000, max_clients=1000))
    server.start()
    budget = len(__import__("os").listdir("/proc/self/fd")) + 4
    resource.setrlimit(resource.RLIMIT_NOFILE, (budget, resource.getrlimit(resource.RLIMIT_NOFILE)[1]))
    print(server.address[1], flush=True)
    for line in sys.stdin:
        print(server.protocol.status_line(), flush=True)
""")


def _accept_failures(status: str) -> int:
    """How many times in a row the listener failed to accept, as STATUS says (0 without the fault)."""
    found = re.search(r'tcp-accept_fault="cannot accept connections[^"]*\((\d+) failures?', status)
    return int(found.group(1)) if found else 0


def _cpu_seconds(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def test_out_of_descriptors_rests_the_listener_and_recovers() -> None:
    child = subprocess.Popen([sys.executable, "-c", CHILD], cwd=ROOT, stdin=subprocess.PIPE,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    clients: list[LineClient] = []
    try:
        port = int(child.stdout.readline())
        for _ in range(12):  # more than the child has descriptors for: the rest wait in its backlog
            clients.append(LineClient(("127.0.0.1", port)))
        def status() -> str:
            child.stdin.write("status\n")
            child.stdin.flush()
            return child.stdout.readline()

        # the child has hit EMFILE once its STATUS shows the fault
        wait_for(lambda: 'tcp-accept_fault="cannot accept connections' in status(), 10.0, "the tcp-accept fault",
                 interval_s=0.05)
        # The window the CPU is measured over: until the listener has tried twice more (its back-off doubles
        # from 0.1 s, so at least 0.3 s), read from STATUS every 0.1 s.
        first = _accept_failures(status())
        cpu_before, began = _cpu_seconds(child.pid), time.monotonic()
        wait_for(lambda: _accept_failures(status()) >= first + 2, 20.0, "two more tries to accept", interval_s=0.1)
        spent, took = _cpu_seconds(child.pid) - cpu_before, time.monotonic() - began
        assert spent < 0.3 * took, f"the accept loop used {spent:.2f} s of CPU in {took:.2f} s out of descriptors"
        assert 'tcp-accept_fault="cannot accept connections' in status()
        for c in clients:
            c.close()
        clients.clear()
        # the fault clears at the end of its back-off (<= 5 s), with no peer waiting: the server finds a spare
        # descriptor itself
        wait_for(lambda: "faults=none" in status(), 10.0, "tcp-accept to clear with descriptors free",
                 interval_s=0.2)
        late = LineClient(("127.0.0.1", port))
        clients.append(late)
        assert late.read_line(timeout=10.0) == b"Hello, this is Nova for Windows.\r\n"
        child.stdin.write("status\n")
        child.stdin.flush()
        assert "faults=none" in child.stdout.readline()
    finally:
        for c in clients:
            c.close()
        child.kill()
        _, err = child.communicate(timeout=10)
    assert "Traceback" not in err
    assert err.count("cannot accept connections") == 1, err
