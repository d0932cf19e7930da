"""The test daemons themselves: a test must never talk, unknowingly, to another test's daemon."""

from __future__ import annotations

import socket
from pathlib import Path

import pytest

from tests.hamlib_daemons import HamlibDaemon
from tests.waiting import wait_for


def test_a_port_taken_before_the_daemon_binds_it_is_not_mistaken_for_the_daemon() -> None:
    """Tests run in parallel: another listener can take the chosen port before rigctld binds it.  The old
    helper connected to that listener and returned; now the daemon, unable to bind, is started again on
    another port and answers there."""
    squatter = socket.socket()
    try:
        squatter.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        daemon = HamlibDaemon("rigctld")
        taken = daemon.port
        squatter.bind(("127.0.0.1", taken))
        squatter.listen()
        with daemon:
            assert daemon.port != taken
            assert daemon.query("f")[0].isdigit()  # a dummy rig's frequency, from the daemon itself
    finally:
        squatter.close()


_RECORDING_LISTENER = """#!/usr/bin/env python3
import socket, sys
args = sys.argv[1:]
port, log = int(args[args.index("-t") + 1]), args[-1]
server = socket.socket()
server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
server.bind(("127.0.0.1", port))
server.listen()
while True:
    client, (_, peer) = server.accept()
    with open(log, "a") as out:
        out.write(f"{peer}\\n")
    client.close()
"""


@pytest.mark.skipif(not Path("/proc/net/tcp").exists(), reason="without /proc the helper must probe the port")
def test_starting_a_daemon_makes_no_connection_to_it(tmp_path) -> None:
    """Hamlib 4.5's rigctld/rotctld close a finished client's descriptor three times, so a connection that ends
    while the next one is accepted can shut that next one (the test's first client: "Connection reset by
    peer").  The helper used to probe the port with a connection it closed at once; it now reads /proc, so the
    test's own client is the first the daemon ever accepts."""
    program = tmp_path / "listener"
    program.write_text(_RECORDING_LISTENER)
    program.chmod(0o755)
    log = tmp_path / "accepted"
    log.touch()
    daemon = HamlibDaemon("rigctld", extra=[str(log)])
    daemon.program = str(program)  # stands in for the daemon: it records each connection it accepts
    with daemon, socket.create_connection((daemon.host, daemon.port), timeout=5) as first:
        ours = str(first.getsockname()[1])
        wait_for(lambda: ours in log.read_text().split(), 10.0, "the listener to accept our connection")
    assert log.read_text().split() == [ours]  # the old helper's probe connection was listed before ours
