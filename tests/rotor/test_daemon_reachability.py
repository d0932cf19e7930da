"""A daemon never reached is "not reachable at HOST:PORT"; "lost" only once a connection was made (#25 item 9).

A real rotctld on a loopback port: first nothing listens there, then the daemon starts, answers, and is killed."""

from __future__ import annotations

from datetime import datetime, timezone

import pytest

from nfwserver.clock import VirtualClock
from nfwserver.hamlib.commands import GET_POSITION
from nfwserver.hamlib.connection import HamlibConnection, HamlibUnavailable
from tests.hamlib_daemons import HamlibDaemon


@pytest.mark.hamlib
def test_not_reachable_until_the_first_connection_then_lost() -> None:
    clock = VirtualClock(datetime(2026, 5, 8, tzinfo=timezone.utc))
    daemon = HamlibDaemon("rotctld")  # its port is free: nothing listens yet
    where = f"127.0.0.1:{daemon.port}"
    link = HamlibConnection("127.0.0.1", daemon.port, clock, name="rotctld")
    with pytest.raises(HamlibUnavailable) as info:
        link.call(GET_POSITION)
    assert str(info.value) == f"rotctld not reachable at {where} (connection refused)"
    assert link.health.fault is not None and link.health.fault.reason == str(info.value)
    clock.advance(5)
    with pytest.raises(HamlibUnavailable, match=f"^rotctld not reachable at {where} "):
        link.call(GET_POSITION)  # still never connected
    with daemon:
        clock.advance(5)
        assert len(link.call(GET_POSITION)) == 2 and link.health.ok
        daemon.kill()
        with pytest.raises(HamlibUnavailable) as info:
            link.call(GET_POSITION)
        assert str(info.value).startswith(f"rotctld at {where} lost (")
        clock.advance(5)
        with pytest.raises(HamlibUnavailable) as info:
            link.call(GET_POSITION)
        assert str(info.value) == f"rotctld at {where} lost (connection refused)"
        assert "Errno" not in link.health.fault.reason
