"""``nfwserver simulate``: flags, output format, pokes, and bad input."""

from __future__ import annotations

import re
import time

import pytest

from nfwserver.cli import main
from nfwserver.clock import SystemClock
from nfwserver.core.publisher import Publisher
from tests.conftest import DATA
from tests.dde.conftest import make_station

LINE = re.compile(r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z\t\S+ AZ:\S+ EL:\S+ RR:\S+ AH:[YN]$")
BASE = ["simulate", "--elements", str(DATA / "visual.txt"), "--observer", "-33.87,151.21,40",
        "--start", "2026-05-08T00:00:00"]


def test_output_lines_times_and_pokes(capsys) -> None:
    assert main([*BASE, "--duration", "60", "--rate", "2", "--sat", "25544",
                 "--poke", "10:TUNE OFF", "--poke", "20:TUNE ON", "--poke", "30:SAT=99999"]) == 0
    out, err = capsys.readouterr()
    lines = out.splitlines()
    assert all(LINE.match(line) for line in lines)
    assert lines[0].startswith("2026-05-08T00:00:00.000Z\tISS ")
    assert lines[1].startswith("2026-05-08T00:00:00.500Z\t")
    times = [line[17:23] for line in lines]
    assert "10.000" not in times and "19.500" not in times and "20.000" in times
    assert len(lines) == 121 - 20
    assert "99999" in err and "not in the catalog" in err


def test_a_45_minute_session_at_5_hz_runs_fast(capsys) -> None:
    started = time.perf_counter()
    assert main([*BASE, "--duration", "2700", "--sat", "25544"]) == 0
    assert len(capsys.readouterr().out.splitlines()) == 13501
    assert time.perf_counter() - started < 30  # generous bound: far faster than real time


def test_without_a_satellite_nothing_is_published_and_it_says_why(capsys) -> None:
    assert main([*BASE, "--duration", "5"]) == 0
    out, err = capsys.readouterr()
    assert out == "" and "no --sat" in err


@pytest.mark.parametrize(
    ("extra", "message"),
    [(["--rate", "100"], "--rate"), (["--start", "yesterday"], "--start"), (["--duration", "-1"], "--duration")],
)
def test_bad_input_is_one_sentence_and_exit_1(capsys, extra, message) -> None:
    args = [a for a in BASE if a not in ("--start", "2026-05-08T00:00:00")] if "--start" in extra else BASE
    assert main([*args, "--sat", "25544", *extra]) == 1
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err


def test_bad_observer_and_missing_file(capsys, tmp_path) -> None:
    assert main(["simulate", "--elements", str(tmp_path / "none.txt"), "--observer", "1,2",
                 "--start", "2026-05-08T00:00:00", "--sat", "1"]) == 1
    assert "no usable element sets" in capsys.readouterr().err
    with pytest.raises(SystemExit) as info:
        main(["simulate", "--observer", "1,2"])
    assert info.value.code == 2


def test_real_time_publisher_ticks_at_its_rate_and_stops() -> None:
    station = make_station(rate_hz=50.0)
    station.core.clock = SystemClock()
    publisher = Publisher(station.core, SystemClock())
    publisher.start()
    time.sleep(0.25)
    publisher.stop()
    assert 8 <= publisher.stats.ticks <= 16
    assert publisher.stats.failures == 0
