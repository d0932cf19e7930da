"""The Windows suite under Wine, driven from Linux (``tools/wine/test``; ``.ci/run`` after the Linux suite).

Skipped unless ``NFW_WINE_SUITE=1``; with it set, a missing Wine prefix is a failure, not a skip.
What runs:

- the in-Wine pytest of ``tests/windows`` (DDEML clients, public-client behaviours, pywin32),
  which must pass with nothing skipped;
- ``tools/wine/nfwserver run --headless --config FILE`` serving ``NFW32`` and ``NFW_SERVER`` to 20
  DDEML clients in another process started with ``tools/wine/run``: hot advise loops at 10 Hz for
  60 s, every conversation kept, then ``XTYP_DISCONNECT`` to each when the station stops;
- docs/WINE.md's set-up: a Windows DDE client under Wine pointing a Linux ``rotctld`` over TCP
  from the station's feed, while the station under Wine tunes a Linux ``rigctld``.
- SIGTERM, SIGINT and SIGHUP to ``tools/wine/nfwserver`` stop the Windows station cleanly within 5 s.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from nfwserver.dde.post_advise_stats import parse_summary
from tests.waiting import wait_for
from tests.windows.station_config import write_station_config
from tests.windows.wine_session import kill_session

ROOT = Path(__file__).resolve().parent.parent.parent
WINE = ROOT / "tools" / "wine"
NOVA = r"^\S{1,12} AZ:\d{1,3}\.\d EL:-?\d{1,2}\.\d RR:-?\d+\.\d{10} AH:[YN]$"

pytestmark = [
    pytest.mark.skipif(os.environ.get("NFW_WINE_SUITE") != "1",
                       reason="the Windows suite under Wine runs with tools/wine/test (NFW_WINE_SUITE=1)"),
    pytest.mark.skipif(sys.platform == "win32", reason="drives Wine from Linux"),
    pytest.mark.timeout(400),
]


def winpath(path: Path) -> str:
    return "Z:" + str(path.resolve()).replace("/", "\\")


@pytest.fixture(scope="module", autouse=True)
def prefix_ready() -> None:
    home = Path(os.environ.get("NFW_WINE_HOME", Path.home() / ".cache" / "nfwserver" / "wine"))
    if not (home / "stamps" / "ready").exists():
        pytest.fail(f"no Wine prefix at {home}: run tools/wine/setup (tools/wine/test does)")


def wine_run(*args: str, timeout: float) -> subprocess.CompletedProcess[str]:
    return subprocess.run([str(WINE / "run"), *args], cwd=ROOT, stdin=subprocess.DEVNULL, capture_output=True,
                          text=True, timeout=timeout, env={**os.environ, "NFW_WINE_TIMEOUT": str(int(timeout))})


def start_station(config: Path, duration_s: float, log: Path) -> subprocess.Popen[str]:
    """The station in a session of its own, so that :func:`kill_session` ends python.exe too."""
    return subprocess.Popen(
        [str(WINE / "nfwserver"), "run", "--headless", "--config", winpath(config), "--log-file", winpath(log),
         "--duration", str(duration_s)],
        cwd=ROOT, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        start_new_session=True,
    )


def test_windows_suite_passes_under_wine_with_nothing_skipped(tmp_path) -> None:
    report = tmp_path / "junit.xml"
    done = wine_run("python", "-m", "pytest", "tests/windows", "-p", "no:randomly", "-q", "-rs",
                    "--ignore=tests/windows/test_wine_suite.py", "--ignore=tests/windows/test_platform_transport.py",
                    "--ignore=tests/windows/test_wine_session.py", "--ignore=tests/windows/test_installer.py",
                    f"--junitxml={winpath(report)}", timeout=240)
    assert report.exists(), done.stdout[-3000:] + done.stderr[-3000:]
    suite = ET.parse(report).getroot()
    suite = suite if suite.tag == "testsuite" else suite.find("testsuite")
    counts = {k: int(suite.get(k, 0)) for k in ("tests", "failures", "errors", "skipped")}
    assert done.returncode == 0, done.stdout[-4000:]
    assert counts["tests"] >= 21 and counts["failures"] == counts["errors"] == counts["skipped"] == 0, counts


def test_launcher_station_serves_20_clients_at_10_hz_for_60_s_and_disconnects_them(tmp_path) -> None:
    """20 conversations from 10 client programs (two each: NFW32 and NFW_SERVER), all started with
    tools/wine/run against a station started with tools/wine/nfwserver."""
    import re

    config = write_station_config(tmp_path, elements=Path(winpath(ROOT / "tests" / "data" / "visual.txt")))
    station = start_station(config, 85, tmp_path / "station.log")
    outs = [tmp_path / f"clients{i}.json" for i in range(10)]
    programs = [subprocess.Popen(
        [str(WINE / "run"), "python", winpath(ROOT / "tests" / "windows" / "dde_clients.py"), "--clients", "2",
         "--seconds", "60", "--wait-disconnect", "45", "--out", winpath(out)],
        cwd=ROOT, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        env={**os.environ, "NFW_WINE_TIMEOUT": "200"}, start_new_session=True) for out in outs]
    try:
        for program in programs:
            program.communicate(timeout=220)
        stdout, stderr = station.communicate(timeout=60)
    finally:
        for proc in (*programs, station):
            kill_session(proc)
    assert station.returncode == 0, stderr[-3000:]
    assert "serving real DDE (DDEML)" in stderr
    # The station logged its DDEML cost when it stopped: one DdePostAdvise per tick, most at 20 links.
    cost = parse_summary((tmp_path / "station.log").read_text(encoding="utf-8", errors="replace"))
    assert cost is not None and cost["links"] == 20 and cost["steady_count"] >= 300, cost
    results = [r for out in outs for r in json.loads(out.read_text())]
    assert len(results) == 20 and all(r["error"] is None for r in results), results
    assert sorted(r["service"] for r in results) == ["NFW32"] * 10 + ["NFW_SERVER"] * 10
    for r in results:
        assert r["still_connected"], r
        assert re.match(NOVA, r["request_after"]), r
        assert 0.95 * 10 * r["window_s"] <= r["advise"] <= 1.05 * 10 * r["window_s"] + 1, r  # rate held
        assert re.match(NOVA, r["sample"]), r
        # The station ended every conversation when it stopped: XTYP_DISCONNECT on Windows; Wine's client
        # DDEML never calls XTYP_DISCONNECT, so there the conversation reports itself terminated.
        assert r["disconnected"], r


def test_wine_md_windows_rotor_client_and_station_radio_reach_linux_hamlib(tmp_path, rotctld, rigctld) -> None:
    """docs/WINE.md: everything Windows under Wine, the Hamlib daemons on Linux, TCP in between."""
    import re

    active = (ROOT / "tests" / "data" / "active.txt").read_text().splitlines()
    at = next(i for i, line in enumerate(active) if line.startswith("1 24307U"))  # INMARSAT 3-F2, geostationary
    elements = tmp_path / "geo.txt"
    elements.write_text("\n".join(active[at - 1:at + 2]) + "\n")
    extra = (f"[rotor]\nbackend = 'none'\n[radio]\nbackend = 'rigctld'\nport = {rigctld.port}\nenabled = true\n"
             "[[satellites.channels]]\ncatalog_number = 24307\nname = 'beacon'\ndownlink_hz = 1537700000\n")
    config = write_station_config(tmp_path, satellite=24307, elements=Path(winpath(elements)),
                                  observer="20.0,-12.0,0", extra=extra)
    station = start_station(config, 40, tmp_path / "station.log")
    try:
        out = tmp_path / "rotor.json"
        client = wine_run("python", winpath(ROOT / "tests" / "windows" / "dde_rotor_client.py"),
                          "--rotctld", f"127.0.0.1:{rotctld.port}", "--seconds", "6", "--out", winpath(out),
                          timeout=120)
        assert client.returncode == 0 and out.exists(), client.stdout[-2000:] + client.stderr[-2000:]
        radio_hz = int(rigctld.query("f")[0])
    finally:
        kill_session(station)
    result = json.loads(out.read_text())
    match = re.search(r" AZ:(\S+) EL:(\S+) ", result["last"])
    assert match and re.match(NOVA, result["last"])
    az, el = float(match.group(1)), float(match.group(2))
    # Independent oracle: skyfield, for the same elements and observer, now (the satellite moves
    # less than 0.05 deg in the seconds between the string and this line).
    from skyfield.api import EarthSatellite, load, wgs84

    ts = load.timescale()
    sat = EarthSatellite(active[at], active[at + 1], ts=ts)
    alt, azimuth, _ = (sat - wgs84.latlon(20.0, -12.0, 0.0)).at(ts.now()).altaz()
    assert abs(el - alt.degrees) < 0.3 and abs(az - azimuth.degrees) < 0.3, (az, el, azimuth.degrees, alt.degrees)
    # The Linux rotor points where DDE said.  rotctld's dummy rotor slews at 6 deg/s from 0/0 (Hamlib's
    # rot_dummy.c), so reaching AZ 180 takes 30 s after the client's P: wait for it (up to 60 s).
    pos: list[float] = []

    def pointed() -> bool:
        pos[:] = [float(v) for v in rotctld.query("p", lines=2)]
        return abs(pos[0] - az) < 0.11 and abs(pos[1] - el) < 0.11

    wait_for(pointed, 60.0, lambda: f"the rotor at {az}/{el} (it is at {pos})", interval_s=0.5)
    assert abs(radio_hz - 1_537_700_000) < 1_537_700_000 * 1 / 299792.458  # tuned: within 1 km/s of Doppler


def _station_processes(marker: str) -> list[int]:
    """Pids of live processes whose command line holds ``marker`` (the station's unique config path)."""
    found = []
    for cmdline in Path("/proc").glob("[0-9]*/cmdline"):
        try:
            text = cmdline.read_bytes().replace(b"\0", b" ").decode("utf-8", "replace")
            state = (cmdline.parent / "stat").read_text().rsplit(")", 1)[1].split()[0]
        except (OSError, IndexError):
            continue
        if marker in text and state != "Z":
            found.append(int(cmdline.parent.name))
    return found


@pytest.mark.parametrize("how", ["SIGTERM to the launcher", "SIGINT to its process group",
                                 "SIGHUP to its process group"])
def test_a_signal_to_the_launcher_stops_the_windows_station_cleanly_within_5_s(tmp_path, how) -> None:
    """What systemd (SIGTERM to the main process) and a terminal (Ctrl+C, hang-up: the foreground process
    group) send: the station under Wine saves its state, ends its DDE conversations and exits 0, and no
    process of it is left."""
    import signal
    import time

    from tests.windows.wine_session import session_members

    sig = getattr(signal, how.split()[0])
    state = tmp_path / "state.json"
    config = write_station_config(tmp_path, elements=Path(winpath(ROOT / "tests" / "data" / "visual.txt")),
                                  state_file=winpath(state))
    station = start_station(config, 120, tmp_path / "station.log")
    out, ready = tmp_path / "clients.json", tmp_path / "ready"
    client = subprocess.Popen(
        [str(WINE / "run"), "python", winpath(ROOT / "tests" / "windows" / "dde_clients.py"), "--clients", "2",
         "--seconds", "2", "--poke", "SAT=694", "--wait-disconnect", "30", "--ready", winpath(ready),
         "--out", winpath(out)],
        cwd=ROOT, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        env={**os.environ, "NFW_WINE_TIMEOUT": "120"}, start_new_session=True)
    try:
        def clients_ready() -> bool:
            if client.poll() is not None:  # its own words (a traceback) say why, not just its exit status
                raise AssertionError(f"the DDE client program exited {client.returncode} before it was ready: "
                                     f"{client.communicate()[0][-3000:]}")
            assert station.poll() is None, station.poll()
            return ready.exists()

        wait_for(clients_ready, 90.0, "the DDE clients to be connected", interval_s=0.1)
        if how.endswith("process group"):
            os.killpg(station.pid, sig)
        else:
            station.send_signal(sig)
        started = time.monotonic()
        stdout, stderr = station.communicate(timeout=30)
        took = time.monotonic() - started
        client_out, _ = client.communicate(timeout=60)
    finally:
        for proc in (client, station):
            kill_session(proc)
    assert station.returncode == 0 and took < 5.0, (station.returncode, took, stderr[-3000:])
    assert "Traceback" not in stderr
    log = (tmp_path / "station.log").read_text(encoding="utf-8", errors="replace")
    assert "control file" in log and log.rstrip().endswith("stopped"), log[-2000:]
    assert '"satellite": 694' in state.read_text()  # the run-time choice survives the stop
    results = json.loads(out.read_text())
    assert len(results) == 2 and all(r["disconnected"] for r in results), (results, client_out[-2000:])
    assert session_members(station.pid) == []
    assert _station_processes(winpath(config)) == []
