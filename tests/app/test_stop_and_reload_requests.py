"""The parts behind ``run``'s signal handling: real signals to this process through StationSignals, the control
file, and a configuration read on request."""

from __future__ import annotations

import logging
import os
import signal
import sys
import threading
from pathlib import Path

import pytest

from nfwserver.app.config_watcher import ConfigWatcher
from nfwserver.cli.control_file import ControlFile, control_path
from nfwserver.cli.signals import RELOAD, STOP, StationSignals, signal_actions
from nfwserver.clock import SystemClock
from tests.waiting import wait_for


def test_sighup_reloads_when_headless_and_stops_under_the_console() -> None:
    assert signal_actions(headless=True)[signal.SIGTERM] == STOP
    assert signal_actions(headless=True)[signal.SIGINT] == STOP
    if hasattr(signal, "SIGHUP"):
        assert signal_actions(headless=True)[signal.SIGHUP] == RELOAD
        assert signal_actions(headless=False)[signal.SIGHUP] == STOP


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_real_signals_become_one_stop_and_reloads_and_later_ones_are_only_noted(caplog) -> None:
    saved = {sig: signal.getsignal(sig) for sig in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP)}
    calls: list[str] = []
    signals = StationSignals(signal_actions(headless=True), lambda: calls.append("stop"),
                             lambda: calls.append("reload"))
    try:
        with caplog.at_level(logging.INFO, logger="nfwserver"):
            assert signals.install()
            os.kill(os.getpid(), signal.SIGHUP)
            assert wait_for(lambda: calls == ["reload"])
            os.kill(os.getpid(), signal.SIGTERM)
            assert wait_for(lambda: calls == ["reload", "stop"])
            os.kill(os.getpid(), signal.SIGINT)  # a second Ctrl+C while stopping: no KeyboardInterrupt
            os.kill(os.getpid(), signal.SIGHUP)  # and no reload once stopping
            assert wait_for(lambda: caplog.text.count("already stopping") == 2)
            assert calls == ["reload", "stop"]
            signals.close()
            os.kill(os.getpid(), signal.SIGINT)  # after the run: ignored (a handler would run as kill returns)
        assert "SIGHUP: reloading the configuration" in caplog.text and "SIGTERM: stopping" in caplog.text
    finally:
        for sig, handler in saved.items():
            signal.signal(sig, handler)


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_signals_handled_by_others_are_not_requests_and_any_thread_may_take_ours() -> None:
    """The wakeup descriptor carries every signal with a Python handler: the console's own (Textual handles
    SIGTSTP and SIGCONT: Ctrl+Z, fg) must not stop the station.  A SIGTERM the system hands to another thread
    than the main one is acted on while the main thread waits (as the station's does, for minutes); before, it
    waited for the main thread's next bytecode (a station suspended and continued kept running)."""
    saved = {sig: signal.getsignal(sig) for sig in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP, signal.SIGCONT)}
    calls: list[str] = []
    stopped = threading.Event()
    signals = StationSignals(signal_actions(headless=True), lambda: (calls.append("stop"), stopped.set()),
                             lambda: calls.append("reload"))
    try:
        assert signals.install()
        signal.signal(signal.SIGCONT, lambda *_: None)  # as the console's driver does
        os.kill(os.getpid(), signal.SIGCONT)
        os.kill(os.getpid(), signal.SIGHUP)
        assert wait_for(lambda: calls == ["reload"])  # the SIGCONT before it asked for nothing
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGTERM})  # so another thread (nfw-signals) takes it
        try:
            os.kill(os.getpid(), signal.SIGTERM)
            assert stopped.wait(5.0)  # the main thread blocked in a wait, as the station's
        finally:
            signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGTERM})
        assert calls == ["reload", "stop"]
    finally:
        signals.close()
        for sig, handler in saved.items():
            signal.signal(sig, handler)


def test_off_the_main_thread_nothing_is_installed() -> None:
    result: list[bool] = []
    signals = StationSignals(signal_actions(headless=True), lambda: None, lambda: None)
    worker = threading.Thread(target=lambda: result.append(signals.install()))
    worker.start()
    worker.join()
    signals.close()
    assert result == [False]


def test_the_control_file_asks_for_reload_and_stop_and_is_removed(tmp_path: Path, caplog) -> None:
    path = tmp_path / "control"
    assert control_path({"NFW_CONTROL_FILE": str(path)}) == path and control_path({}) is None
    got: list[tuple[str, str]] = []
    looks = [0]  # each_look's calls: one per look

    def looked() -> None:
        looks[0] += 1

    control = ControlFile(path, SystemClock(), lambda word, origin: got.append((word, origin)), interval_s=0.01,
                          each_look=looked)
    path.write_text("stop\n")  # left by an earlier run: removed at start, never acted on
    control.start()
    try:
        assert not path.exists()
        path.write_text("")  # being written: left alone, look after look
        seen = looks[0]
        assert wait_for(lambda: looks[0] >= seen + 3)
        assert path.exists() and got == []
        path.write_text("RELOAD\n")
        assert wait_for(lambda: len(got) == 1) and not path.exists()
        path.write_text("halt now\n")
        assert wait_for(lambda: not path.exists())  # removed first, then said: wait for the line itself
        assert wait_for(lambda: "'halt' is not a request" in caplog.text)
        path.write_text("stop")
        assert wait_for(lambda: len(got) == 2)
    finally:
        control.stop()
    assert got == [("reload", f"control file {path}"), ("stop", f"control file {path}")]


def test_a_requested_read_applies_the_file_even_when_it_looks_unchanged(tmp_path: Path) -> None:
    path = tmp_path / "station.toml"
    path.write_text('[server]\nsatellite = 25544\n')
    applied: list[int | None] = []
    refused: list[str] = []
    watcher = ConfigWatcher(path, SystemClock(), lambda c: applied.append(c.server.satellite), refused.append,
                            interval_s=None)
    watcher.start()
    try:
        stat = path.stat()
        path.write_text('[server]\nsatellite = 27607\n')  # same size, same time: a watcher sees no change
        os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns))
        assert applied == []  # the watcher does not poll (interval_s=None): it reads only when asked
        watcher.request()
        assert wait_for(lambda: applied == [27607])
        path.write_text("# being saved\n")
        watcher.request()
        assert wait_for(lambda: len(refused) == 1) and applied == [27607]
    finally:
        watcher.stop()


def test_a_reload_asked_for_while_the_station_starts_is_carried_out_once_it_is_up(tmp_path, caplog) -> None:
    """A SIGHUP between reading the configuration and the station being up was logged as a reload and then
    dropped; it is now kept and carried out when the station is up (one reload, not one per request)."""
    from nfwserver.app.station import Station
    from nfwserver.cli.run_command import _Requests
    from nfwserver.clock import VirtualClock
    from nfwserver.config.loader import load_config
    from nfwserver.fake_dde import FakeDdeSystem
    from tests.dde.conftest import ISS_PASS

    path = tmp_path / "station.toml"
    path.write_text('[observer]\nlocation = "JO02ae"\n[server]\nstate_file = "none"\n')
    station = Station(load_config(str(path)), VirtualClock(ISS_PASS.aos), transport=FakeDdeSystem().server_transport())
    requests = _Requests(threading.Event())
    caplog.set_level(logging.INFO, logger="nfwserver.app.station")
    requests.on_reload()
    requests.on_reload()
    assert not [r for r in caplog.records if "reloading the configuration" in r.getMessage()]
    station.start()
    try:
        requests.station_started(station)
        reloads = [r for r in caplog.records if "reloading the configuration" in r.getMessage()]
        assert len(reloads) == 1 and str(path) in reloads[0].getMessage()
        requests.on_reload()  # from now on each request reaches the station at once
        assert len([r for r in caplog.records if "reloading the configuration" in r.getMessage()]) == 2
    finally:
        station.stop()


def test_a_request_withdrawn_before_the_station_removed_it_is_not_acted_on(tmp_path: Path, caplog) -> None:
    """#42 item 12 (Windows' `stop`): a writer that gives up removes its request again; the station acts only on
    a request it removed itself, so "withdrawn" is exactly true.  The interleaving is made real with a FIFO: the
    station's read ends only when the writer closes it, and the writer removes the name first."""
    path = tmp_path / "control"
    got: list[str] = []
    control = ControlFile(path, SystemClock(), lambda word, origin: got.append(word))
    os.mkfifo(path)

    def write_then_withdraw() -> None:
        with open(path, "w") as fifo:
            fifo.write("stop\n")
            fifo.flush()
            path.unlink()  # withdrawn after the station has it to read, before it could remove it

    writer = threading.Thread(target=write_then_withdraw)
    writer.start()
    caplog.set_level(logging.INFO, logger="nfwserver")
    assert control.check() is None  # one look: read "stop", found it gone
    writer.join()
    assert got == [] and "the request was withdrawn before it was read" in caplog.text


def test_the_state_folders_control_file_is_watched_beside_the_environments(tmp_path: Path) -> None:
    """The station always watches its state folder's `control` (where `stop` writes on Windows), also when
    NFW_CONTROL_FILE names another file (the Wine launcher's)."""
    named, own = tmp_path / "named", tmp_path / "control"
    got: list[tuple[str, str]] = []
    control = ControlFile(named, SystemClock(), lambda word, origin: got.append((word, origin)), also=own)
    own.write_text("stop\n")
    assert control.check() == "stop" and got == [("stop", f"control file {own}")] and not own.exists()
    named.write_text("reload\n")
    assert control.check() == "reload" and got[-1] == ("reload", f"control file {named}")
