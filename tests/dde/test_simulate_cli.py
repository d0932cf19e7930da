"""``nfwserver simulate``: flags, output format, pokes, the station defaults, and bad input."""

from __future__ import annotations

import re
import time
from datetime import datetime, timedelta, timezone
from pathlib import Path

import pytest

from nfwserver.cli import main
from nfwserver.clock import SystemClock
from nfwserver.core.publisher import Publisher
from tests.conftest import DATA
from tests.dde.conftest import make_station
from tests.waiting import wait_for

LINE = re.compile(r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z\t\S+ AZ:\S+ EL:\S+ RR:\S+ AH:[YN]$")
BASE = ["simulate", "--elements", str(DATA / "visual.txt"), "--observer", "-33.87,151.21,40",
        "--start", "2026-05-08T00:00:00"]


def test_output_lines_times_and_pokes(capsys) -> None:
    assert main([*BASE, "--duration", "60", "--rate", "2", "--sat", "25544", "--poke", "0:TUNE ON",
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


def test_tune_on_is_poked_automatically_only_without_a_tune_poke(capsys) -> None:
    assert main([*BASE, "--duration", "10", "--sat", "25544", "--poke", "5:TUNE ON"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("2026-05-08T00:00:05.000Z\tISS ") and len(lines) == 26  # nothing before TUNE ON
    assert main([*BASE, "--duration", "10", "--sat", "25544", "--poke", "5:TRACK ON"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("2026-05-08T00:00:00.000Z\tISS ") and len(lines) == 51
    help_text = " ".join(_help(capsys).split())
    assert "TUNE ON is poked at the start unless the first TUNE command among the --poke options is TUNE ON or " \
        "is sent at 0 s" in help_text


def test_each_poke_says_what_it_did_on_stderr(capsys) -> None:
    """The poke goes to the core through the DDE client; its answer and the state change are one line each."""
    assert main([*BASE, "--duration", "120", "--rate", "1", "--sat", "25544", "--poke", "60:TUNE OFF",
                 "--poke", "70:SAT=99999", "--poke", "80:TRACK ON", "--poke", "90:ANTAZ=12.5",
                 "--poke", "100:TUNE OFF"]) == 0
    out, err = capsys.readouterr()
    lines = out.splitlines()
    assert lines[0].startswith("2026-05-08T00:00:00.000Z\tISS ")  # TUNE ON first: the first TUNE poke is OFF
    assert lines[-1].startswith("2026-05-08T00:00:59.000Z\tISS ") and len(lines) == 60
    assert err.splitlines() == [
        "t+60 s  poke 'TUNE OFF': accepted; feed off",
        "t+70 s  poke 'SAT=99999': refused: satellite 99999 is not in the catalog; keeping the current one; "
        "nothing changed",
        "t+80 s  poke 'TRACK ON': accepted; tracking on",
        "t+90 s  poke 'ANTAZ=12.5': accepted; antenna azimuth 12.5 deg",
        "t+100 s  poke 'TUNE OFF': accepted; no change",
    ]


def test_a_poke_on_a_dialect_link_is_reported_too(capsys) -> None:
    assert main([*BASE, "--duration", "20", "--rate", "1", "--sat", "25544", "--link",
                 "Orbitron|Tracking!TrackingDataEx", "--poke", "10:SAT=25544", "--poke", "15:TRACK ON"]) == 0
    assert capsys.readouterr().err.splitlines() == ["t+10 s  poke 'SAT=25544': accepted; no change",
                                                    "t+15 s  poke 'TRACK ON': accepted; tracking on"]


@pytest.mark.parametrize(("poke", "line"), [
    ("60:STATUS", "t+60 s  poke 'STATUS': refused: not a Nova command (TUNE ON|OFF, TRACK ON|OFF, SAT=n, "
                  "ANTAZ=deg, ANTEL=deg, DOPPLER ON|OFF, AUTO ON|OFF); nothing changed"),
    ("60:BOGUS COMMAND", "t+60 s  poke 'BOGUS COMMAND': refused: not a Nova command (TUNE ON|OFF, TRACK ON|OFF, "
                         "SAT=n, ANTAZ=deg, ANTEL=deg, DOPPLER ON|OFF, AUTO ON|OFF); nothing changed"),
    ("60:SAT=ISS", "t+60 s  poke 'SAT=ISS': refused: SAT needs a catalog number, got 'ISS'; nothing changed"),
    ("60:ANTEL=200", "t+60 s  poke 'ANTEL=200': refused: ANTEL 200.0 is outside -90..180 degrees; nothing changed"),
    ("60:TUNE", "t+60 s  poke 'TUNE': refused: TUNE needs ON or OFF; nothing changed"),
    # a CF_TEXT client's code page has no Arabic-Indic digits: they reach the server as '?'
    ("60:SAT=\u0662\u0665\u0665\u0664\u0664",
     "t+60 s  poke 'SAT=\u0662\u0665\u0665\u0664\u0664': refused: SAT needs a catalog number, got '?????'; "
     "nothing changed"),
    ("60:SAT=694\nTUNE OFF", "t+60 s  poke 'SAT=694\\nTUNE OFF': accepted; feed off; satellite 25544 ISS -> "
                              "694 ATLAS-CENT-2"),
    ("60:SAT=7530\nBOGUS", "t+60 s  poke 'SAT=7530\\nBOGUS': refused: not a Nova command (TUNE ON|OFF, "
                           "TRACK ON|OFF, SAT=n, ANTAZ=deg, ANTEL=deg, DOPPLER ON|OFF, AUTO ON|OFF); nothing changed"),
])
def test_any_poke_goes_to_the_server_and_stderr_says_what_it_did(capsys, poke, line) -> None:
    """issue 34 item 6: simulate sends what a client sends, a command the server refuses too."""
    assert main([*BASE, "--duration", "120", "--rate", "1", "--sat", "25544", "--poke", poke]) == 0
    assert capsys.readouterr().err.splitlines() == [line]


def _help(capsys) -> str:
    with pytest.raises(SystemExit):
        main(["simulate", "--help"])
    return capsys.readouterr().out


def test_a_45_minute_session_at_5_hz_runs_fast(capsys) -> None:
    started = time.perf_counter()
    assert main([*BASE, "--duration", "2700", "--sat", "25544"]) == 0
    assert len(capsys.readouterr().out.splitlines()) == 13501
    assert time.perf_counter() - started < 30  # generous bound: far faster than real time


def test_the_configured_satellite_and_names_for_sat(capsys, tmp_path) -> None:
    config = tmp_path / "c.toml"
    config.write_text("[server]\nsatellite = 3669\n")
    assert main([*BASE, "--config", str(config), "--duration", "1"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert len(out) == 6 and all(line.split("\t")[1].startswith("ISIS-1 AZ:") for line in out)
    assert main([*BASE, "--config", str(config), "--duration", "1", "--sat", "iss"]) == 0
    assert all(line.split("\t")[1].startswith("ISS AZ:") for line in capsys.readouterr().out.splitlines())
    assert main([*BASE, "--duration", "1", "--sat", "NO SUCH SAT"]) == 1
    assert "satellite NO SUCH SAT is not in the catalog" in capsys.readouterr().err


def test_without_a_satellite_nothing_is_published_and_the_warning_matches_the_pokes(capsys, tmp_path) -> None:
    config = tmp_path / "c.toml"
    config.write_text("[server]\nsatellite = 99999\n")
    base = [*BASE, "--config", str(config), "--duration", "5"]
    assert main(base) == 0
    out, err = capsys.readouterr()
    assert out == "" and "99999 is not in the catalog" in err and "nothing is published" in err
    assert main([*base, "--poke", "2:SAT=25544"]) == 0
    out, err = capsys.readouterr()
    assert out.startswith("2026-05-08T00:00:02.000Z\tISS ")
    assert "nothing is published until" not in err and "until the SAT= poke at 2 s" in err
    assert main([*base, "--poke", "SAT=25544"]) == 0
    out, err = capsys.readouterr()
    assert out.startswith("2026-05-08T00:00:00.000Z\tISS ") and "nothing" not in err
    assert err.endswith("\nt+0 s  poke 'SAT=25544': accepted; satellite none -> 25544 ISS\n")


def test_the_satellite_warning_reads_the_pokes_as_the_server_does(capsys, tmp_path) -> None:
    """A ``SAT\t=`` poke selects a satellite (the table takes blanks around '='): no false "nothing is
    published"; a poke the server refuses selects none."""
    config = tmp_path / "c.toml"
    config.write_text("[server]\nsatellite = 99999\n")
    base = [*BASE, "--config", str(config), "--duration", "5"]
    assert main([*base, "--poke", "2:SAT\t=25544"]) == 0
    out, err = capsys.readouterr()
    assert out.startswith("2026-05-08T00:00:02.000Z\tISS ")
    assert "so nothing is published" not in err and "until the SAT= poke at 2 s" in err
    assert main([*base, "--poke", "2:SAT=25544 BOGUS"]) == 0
    assert "so nothing is published" in capsys.readouterr().err


def test_a_tune_the_server_refuses_leaves_the_automatic_tune_on(capsys) -> None:
    """The automatic TUNE ON at the start is left out only for a TUNE command the server takes."""
    assert main([*BASE, "--duration", "2", "--rate", "1", "--sat", "25544", "--poke", "1:TUNE ON\nBOGUS"]) == 0
    out, err = capsys.readouterr()
    assert out.startswith("2026-05-08T00:00:00.000Z\tISS ")  # fed from the start: TUNE ON was poked for us
    assert "refused" in err


def test_start_defaults_to_now(capsys) -> None:
    args = [a for a in BASE if a not in ("--start", "2026-05-08T00:00:00")]
    before = datetime.now(timezone.utc)
    assert main([*args, "--duration", "1", "--sat", "25544"]) == 0
    first = capsys.readouterr().out.splitlines()[0].split("\t")[0]
    when = datetime.strptime(first, "%Y-%m-%dT%H:%M:%S.%fZ").replace(tzinfo=timezone.utc)
    assert before - timedelta(seconds=1) <= when <= datetime.now(timezone.utc)


def test_runs_with_no_argument_but_the_duration_after_config_init_and_a_location(capsys, tmp_path) -> None:
    assert main(["config", "init"]) == 0
    path = Path(capsys.readouterr().out.strip().splitlines()[-1].split()[-1])
    text = path.read_text()
    assert '# location = "JO02ae"' in text
    path.write_text(text.replace('# location = "JO02ae"', 'location = "JO02ae"'))
    assert main(["simulate", "--duration", "60"]) == 0
    out, err = capsys.readouterr()
    lines = out.splitlines()
    assert len(lines) == 301 and all(LINE.match(line) for line in lines) and lines[0].split("\t")[1].startswith("ISS ")
    assert "observer" not in err


@pytest.mark.parametrize(
    "extra",
    [["--rate", "500"], ["--start", "yesterday"], ["--duration", "-5"], ["--duration", "0"],
     ["--poke", "abc:TUNE ON"], ["--poke", "-5:TUNE ON"], ["--poke", "61:TUNE OFF"], ["--client", "excel"],
     ["--link", "NFW32/NFW_DATA"], ["--link", "Nobody|Home!Here"], ["--client", "matlab", "--poll", "0"],
     ["--poll", "-1"], ["--observer", "ZZ99zz"], ["--sat", ""]],
)
def test_bad_values_are_usage_errors_exit_2(capsys, extra) -> None:
    args = [a for a in BASE if a not in ("--start", "2026-05-08T00:00:00")] if "--start" in extra else BASE
    with pytest.raises(SystemExit) as info:
        main([*args, "--duration", "60", "--sat", "25544", *extra])
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert "error:" in err and "Traceback" not in err and len(err.strip().splitlines()[-1]) < 300


def test_a_missing_element_file_is_a_runtime_error(capsys, tmp_path) -> None:
    assert main(["simulate", "--elements", str(tmp_path / "none.txt"), "--observer", "1,2",
                 "--start", "2026-05-08T00:00:00", "--sat", "1"]) == 1
    assert f"cannot read {tmp_path / 'none.txt'}: no such file or directory" in capsys.readouterr().err


def test_real_time_publisher_ticks_at_its_rate_and_stops() -> None:
    """On the system clock at 50 Hz, ten ticks take at least nine periods (a schedule is never run ahead of; how
    closely a loaded machine keeps it is measured in bench/, not here), and stop() ends the publishing thread."""
    station = make_station(rate_hz=50.0)
    station.core.clock = SystemClock()
    publisher = Publisher(station.core, SystemClock())
    began = time.monotonic()
    publisher.start()
    thread = publisher.thread
    wait_for(lambda: publisher.stats.ticks >= 10, 10.0, "ten ticks")
    took = time.monotonic() - began
    publisher.stop()
    assert took >= 9 / 50.0
    assert thread is not None and not thread.is_alive()  # no tick can follow
    assert publisher.stats.failures == 0
