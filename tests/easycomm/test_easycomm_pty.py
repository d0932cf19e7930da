"""EasyComm I output on a real pseudo-terminal pair, read from the master side as a controller reads it."""

from __future__ import annotations

import os
import re
import select
from datetime import timedelta
from pathlib import Path

import pytest

from nfwserver.channels.channel import Channel
from nfwserver.config.schema import EasyCommConfig
from nfwserver.easycomm import EasyCommOutput
from nfwserver.easycomm.output import open_serial
from tests.conftest import advance_until
from tests.dde.conftest import CATALOG, ISS, ISS_PASS, OBSERVER, make_station
from tests.tracking.skyfield_oracle import skyfield_look_angles
from tests.waiting import wait_for

C_KM_S = 299792.458
NOVA_LINE = re.compile(r"^AZ(\d{1,3}\.\d) EL(-?\d{1,2}\.\d) UP(-?\d+\.\d{10}) XXX DN000000000 XXX$")
ISS_FM = Channel("ISS FM repeater", 437_800_000, 145_990_000, "FM", "FM")


class Pty:
    """A pseudo-terminal pair; the output opens ``path`` (a symlink, as udev makes for a USB adapter)."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.master, self.slave = os.openpty()
        if path.is_symlink():
            path.unlink()
        path.symlink_to(os.ttyname(self.slave))
        self.pending = b""

    def lines(self, wait_s: float = 0.3) -> list[str]:
        """Every complete line that arrived (waiting up to ``wait_s`` real seconds for more)."""
        while select.select([self.master], [], [], wait_s)[0]:
            try:
                self.pending += os.read(self.master, 4096)
            except OSError:
                break
            wait_s = 0.02
        *done, self.pending = self.pending.split(b"\r\n")
        assert b"\n" not in self.pending and all(b"\r" not in line and b"\n" not in line for line in done)
        return [line.decode("ascii") for line in done]

    def vanish(self) -> None:
        os.close(self.master)
        os.close(self.slave)
        self.path.unlink()


def _output(station, path: Path, uplink: str = "range-rate", **kw) -> EasyCommOutput:
    config = EasyCommConfig(enabled=True, device=str(path), baud=9600, rate_hz=2.0, uplink=uplink)
    output = EasyCommOutput(config, station.core.state, station.clock, **kw)
    station.core.subscribe(output.on_tick)
    return output


def _start(output: EasyCommOutput) -> None:
    """Start the worker and let it open the port and settle into its wait on the virtual clock (it opens at
    once)."""
    output.start()
    wait_for(lambda: output.connected and output.clock.is_waiting(output.thread), 5.0, "the port to open and the "
             "worker to wait for its next line", interval_s=0.001)


def _step(station, output: EasyCommOutput) -> None:
    """Tick once, then let the worker write exactly one line for that tick."""
    station.core.tick()
    written = output.lines_written
    station.clock.advance(0.5)  # one period of the 2 Hz schedule
    wait_for(lambda: output.lines_written != written, 5.0, "the line of that tick", interval_s=0.001)
    assert output.lines_written == written + 1


def ticked(station) -> bool:
    """Tick the core, as the publisher would at this instant; always True (for use inside predicates)."""
    station.core.tick()
    return True


def test_lines_during_a_pass_match_the_spec_and_skyfield(tmp_path) -> None:
    start = ISS_PASS.tca - timedelta(seconds=60)
    dut1 = float(skyfield_look_angles(CATALOG.get(ISS).elements, OBSERVER, [start])[4][0])
    station = make_station(start=start, ut1_utc=dut1)
    pty = Pty(tmp_path / "ttyUSB0")
    output = _output(station, pty.path)
    station.core.set_track(True)
    station.core.set_feed(True)
    _start(output)
    try:
        for _ in range(8):
            _step(station, output)
            sample = station.core.tracker.last_sample
            (line,) = pty.lines()
            m = NOVA_LINE.match(line)
            assert m, line
            az, el, _, rr, _ = skyfield_look_angles(CATALOG.get(ISS).elements, OBSERVER, [sample.time])
            assert abs(float(m.group(1)) - az[0]) <= 0.06 and abs(float(m.group(2)) - el[0]) <= 0.06
            assert abs(float(m.group(3)) - rr[0]) < 1e-3
            assert f"RR:{m.group(3)} " in sample.text  # the same range rate text as the DDE string
            assert output.last_line == line
    finally:
        output.stop()
    assert pty.lines() == ["SA SE"]  # at shutdown


def test_lines_come_at_the_configured_rate_on_the_clock(tmp_path) -> None:
    station = make_station(start=ISS_PASS.tca - timedelta(seconds=60))
    pty = Pty(tmp_path / "ttyUSB0")
    output = _output(station, pty.path)
    station.core.set_track(True)
    station.core.tick()
    output.start()
    try:
        assert advance_until(station.clock, lambda: output.lines_written >= 1, step_s=0.1)
        first = output.lines_written
        # 10.05 s of virtual time in steps the worker follows: its lines fall due 0.5, 1.0, ... 10.0 s after the
        # first (the first came at most one 0.1 s step before this loop; the 0.05 s keeps the line due at 10.0 s
        # on this side of the sum of a hundred 0.1 s steps, which floating point makes 9.99999...).
        for step in [0.1] * 100 + [0.05]:
            station.core.tick()  # as the publisher does
            station.clock.advance(step)
            wait_for(lambda: station.clock.is_waiting(output.thread), 5.0, "the worker to wait for its next line",
                     interval_s=0.001)
        assert output.lines_written - first == 20  # 2 Hz
    finally:
        output.stop()
    assert len([line for line in pty.lines() if line.startswith("AZ")]) == output.lines_written - 1  # + SA SE


def test_stop_lines_when_tracking_stops_and_at_los(tmp_path) -> None:
    station = make_station(start=ISS_PASS.tca)
    pty = Pty(tmp_path / "ttyUSB0")
    output = _output(station, pty.path)
    station.core.set_track(True)
    _start(output)
    try:
        _step(station, output)
        station.core.set_track(False)
        _step(station, output)
        assert [line[:2] for line in pty.lines()] == ["AZ", "SA"] and output.last_line == "SA SE"
        station.clock.set(ISS_PASS.los - timedelta(seconds=2))
        station.core.set_track(True)
        for _ in range(10):  # 5 s across LOS: positions while up, one SA SE at LOS, then silence
            station.core.tick()
            station.clock.advance(0.5)
            wait_for(lambda: station.clock.is_waiting(output.thread), 5.0, "the worker to wait for its next line",
                     interval_s=0.001)
            station.core.tick()
        assert advance_until(station.clock, lambda: output.last_line == "SA SE", step_s=0.5, limit_s=2.0)
        lines = pty.lines()
        assert lines[-1] == "SA SE" and lines.count("SA SE") == 1 and lines[0].startswith("AZ")
        assert not station.core.tracker.last_sample.above_horizon
    finally:
        output.stop()


def test_doppler_mode_carries_the_channel_frequencies_and_modes(tmp_path) -> None:
    station = make_station(start=ISS_PASS.tca - timedelta(seconds=90), channels={ISS: ISS_FM})
    pty = Pty(tmp_path / "ttyUSB0")
    output = _output(station, pty.path, uplink="doppler")
    station.core.set_track(True)
    _start(output)
    try:
        for _ in range(4):
            _step(station, output)
            rr = station.core.tracker.last_sample.look_angles.range_rate_km_s
            (line,) = pty.lines()
            # The spec's formulas: f_tx = f_up (1 + rr/c), f_rx = f_down (1 - rr/c); Hz, nine digits.
            up = round(145_990_000 * (1 + rr / C_KM_S))
            down = round(437_800_000 * (1 - rr / C_KM_S))
            assert line.endswith(f" UP{up:09d} FM DN{down:09d} FM"), line
            assert up != 145_990_000 and down != 437_800_000
    finally:
        output.stop()


def test_the_device_vanishing_and_returning_is_survived_with_capped_back_off(tmp_path, caplog) -> None:
    # The publisher ticks at every step of the clock, as it does in a running station.
    station = make_station(start=ISS_PASS.tca - timedelta(seconds=120))
    pty = Pty(tmp_path / "ttyUSB0")
    attempts: list[float] = []

    def recording_open(device: str, baud: int):
        attempts.append(station.clock.monotonic())
        return open_serial(device, baud)

    output = _output(station, pty.path, max_backoff_s=4.0, open_port=recording_open)
    station.core.set_track(True)
    station.core.tick()
    output.start()
    try:
        assert advance_until(station.clock, lambda: ticked(station) and output.lines_written >= 2, step_s=0.25)
        assert pty.lines()[0].startswith("AZ") and output.connected
        pty.vanish()  # unplugged
        gone = station.clock.monotonic()
        assert advance_until(station.clock, lambda: ticked(station) and len(attempts) >= 7, step_s=0.25, limit_s=60)
        assert not output.connected
        gaps = [b - a for a, b in zip(attempts[1:], attempts[2:])]
        assert gaps[:2] == pytest.approx([2.0, 4.0], abs=0.51) and max(gaps) <= 4.0 + 0.51
        warned = [r.getMessage() for r in caplog.records if r.levelname == "WARNING" and "easycomm" in r.getMessage()]
        assert len(warned) == 1 and warned[0].startswith("easycomm: writing to "), warned  # one line, not one a try
        assert not output.health.ok and output.health.fault is not None and output.health.fault.failures >= 6
        written = output.lines_written
        back = Pty(pty.path)  # plugged in again (a new tty behind the same name)
        assert advance_until(station.clock, lambda: ticked(station) and output.lines_written > written + 1,
                             step_s=0.25, limit_s=10)
        assert station.clock.monotonic() - gone < 60
        assert back.lines()[0].startswith("AZ") and output.connected
        assert output.health.ok  # the first line written cleared the fault
    finally:
        output.stop()


def test_after_the_process_was_stopped_no_line_for_an_old_tick_is_written(tmp_path) -> None:
    # SIGSTOP, then SIGCONT 60 s later: the output's worker may wake before the publisher ticks again, with
    # the newest sample a minute old (ISS moved tens of degrees).  It must write nothing for that sample
    # and write the fresh position as soon as the publisher has ticked.
    station = make_station(start=ISS_PASS.tca - timedelta(seconds=90))
    pty = Pty(tmp_path / "ttyUSB0")
    output = _output(station, pty.path)
    station.core.set_track(True)
    for _ in range(3):
        station.core.tick()
        output.step()
        station.clock.advance(0.5)
    before = pty.lines()
    assert len(before) == 3 and all(NOVA_LINE.match(line) for line in before)
    station.clock.advance(60.0)  # stopped for a minute: no tick, then the worker wakes first
    written = output.lines_written
    output.step()
    assert output.lines_written == written and output.stale_skipped == 1
    assert pty.lines(wait_s=0.05) == []
    fresh = station.core.tick()
    output.step()
    (line,) = pty.lines()
    la = fresh.look_angles
    m = NOVA_LINE.match(line)
    assert m and abs(float(m.group(1)) - la.azimuth_deg) <= 0.05 + 1e-9
    assert abs(float(m.group(2)) - la.elevation_deg) <= 0.05 + 1e-9
    output._close()
