"""The publisher's wake-up of the TCP loop survives the race the campaign found.

``python -m bench reliability`` saw a ``WATCH`` client stop receiving published strings under load: the
loop cleared its "wake pending" flag *before* draining the wake socket, so a tick that set the flag and
sent its byte in between had the byte swallowed by the drain while the flag stayed set; every later tick
then skipped the wake-up, and the loop slept in ``select`` with strings waiting (``stats.lost`` counted
them).  Here the publisher's tick is made to land exactly inside the drain.
"""

from __future__ import annotations

from nfwserver.tcp.server import NovaTcpServer
from tests.tcp.conftest import LineClient
from tests.waiting import wait_for


class _TickDuringDrain:
    """Stands in for the loop's end of the wake socket pair: the first read first runs a tick's
    ``on_tick`` (as the publisher thread would at that moment), then reads for real."""

    def __init__(self, real, server: NovaTcpServer, sample) -> None:
        self.real, self.server, self.sample = real, server, sample
        self.fired = False

    def recv(self, n: int) -> bytes:
        if not self.fired:
            self.fired = True
            self.server.on_tick(self.sample)
        return self.real.recv(n)

    def __getattr__(self, name: str):
        return getattr(self.real, name)


def test_a_tick_landing_inside_the_drain_does_not_stop_later_wake_ups(tcp_station) -> None:
    station, server = tcp_station
    station.core.set_feed(True)
    watcher = LineClient(server.address)
    try:
        assert watcher.read_line() == b"Hello, this is Nova for Windows.\r\n"
        watcher.send(b"WATCH\r\n")
        assert watcher.read_line() == b"OK\r\n"
        assert wait_for(lambda: server.watcher_count() == 1)
        sample = station.core.tick()
        assert sample.text and watcher.text() == sample.text
        server._wake_r = _TickDuringDrain(server._wake_r, server, sample)
        station.core.tick()  # wakes the loop; its drain runs the extra tick
        assert [watcher.text(), watcher.text()] == [sample.text] * 2
        for _ in range(5):  # later ticks must each reach the watcher
            station.core.tick()
        assert [watcher.text(timeout=2.0) for _ in range(5)] == [sample.text] * 5
        assert server.stats.lost == 0
    finally:
        watcher.close()
