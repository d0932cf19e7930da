"""The test daemons themselves: a test must never talk, unknowingly, to another test's daemon."""

from __future__ import annotations

import socket

from tests.hamlib_daemons import HamlibDaemon


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
