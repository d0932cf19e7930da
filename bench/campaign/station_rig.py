"""A real Station for the campaign, with everything a hostile client can reach switched on.

:class:`StationRig` starts ``nfwserver.app.station.Station`` on the system clock with the in-process DDE
transport (FakeDdeSystem), PREDICT UDP and Nova's TCP server on 127.0.0.1 ephemeral ports, the element
store and session state in a work directory, and -- when ``rotctld``/``rigctld`` are installed -- the real
Hamlib daemons (tests/hamlib_daemons.py) behind the rotor and radio.  Two clients watch what it publishes:
a hot DDE advise loop and a TCP ``WATCH`` connection.  :meth:`StationRig.check` says whether the station
still publishes and whether a watcher missed a string.
"""

from __future__ import annotations

import shutil
import socket
import threading
import time
from collections import Counter
from pathlib import Path

from bench.campaign.fuzz_elements import SOURCE_SETS
from bench.campaign.tally import Tally
from nfwserver.app.session_state import StateFile
from nfwserver.app.station import Station
from nfwserver.clock import SystemClock
from nfwserver.config.loader import parse_config
from nfwserver.fake_dde import FakeDdeSystem
from nfwserver.tracking.elements import load_element_file

GREETING = b"Hello, this is Nova for Windows.\r\n"


def hamlib_available() -> bool:
    return bool(shutil.which("rotctld") and shutil.which("rigctld"))


class TcpWatcher:
    """A TCP client that sends ``WATCH`` and records every line it receives (thread ``campaign-watch``)."""

    def __init__(self, address: tuple[str, int]) -> None:
        self.sock = socket.create_connection(address, timeout=5.0)
        self.lines: list[str] = []
        self.lock = threading.Lock()
        self._buffer = b""
        while self._buffer.count(b"\r\n") < 1:
            self._buffer += self.sock.recv(4096)
        assert self._buffer.startswith(GREETING), self._buffer
        self._buffer = self._buffer[len(GREETING):]
        self.sock.sendall(b"WATCH\r\n")
        while b"\r\n" not in self._buffer:
            self._buffer += self.sock.recv(4096)
        first, self._buffer = self._buffer.split(b"\r\n", 1)
        assert first == b"OK", first
        self.closed = False
        self._thread = threading.Thread(target=self._run, name="campaign-watch", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        self.sock.settimeout(0.2)
        while not self.closed:
            try:
                chunk = self.sock.recv(65536)
            except TimeoutError:
                continue
            except OSError:
                break
            if not chunk:
                break
            self._buffer += chunk
            *done, self._buffer = self._buffer.split(b"\r\n")
            with self.lock:
                self.lines += [line.decode("ascii", errors="replace") for line in done]
        self.closed = True

    def take(self) -> list[str]:
        """The lines received so far; they are forgotten (the campaign's own memory stays bounded)."""
        with self.lock:
            lines, self.lines = self.lines, []
        return lines

    def put_back(self, lines: list[str]) -> None:
        with self.lock:
            self.lines = lines + self.lines

    def close(self) -> None:
        self.closed = True
        self._thread.join(2.0)
        self.sock.close()


class StationRig:
    """See the module docstring.  Use as a context manager; ``daemons`` False leaves rotor and radio out."""

    def __init__(self, workdir: Path, rate_hz: float = 50.0, daemons: bool = True) -> None:
        self.workdir = Path(workdir)
        self.rate_hz = rate_hz
        self.daemons_wanted = daemons and hamlib_available()
        self.rot = self.rig = None
        self.station: Station | None = None
        self.published: list[str] = []  #: strings published since the last check
        self.dde_received: list[str] = []  #: strings the DDE watcher received since the last check
        self.published_total = self.dde_total = self._dde_missing = 0
        self._lock = threading.Lock()
        self.store_path = self.workdir / "elements.txt"
        self.state_path = self.workdir / "state.json"

    # -- life cycle ------------------------------------------------------------------------------------
    def config_text(self) -> str:
        text = (f'[observer]\nlocation = "JO02ae"\n'
                f'[elements]\nfiles = ["{SOURCE_SETS}"]\nuse_bundled = false\nstore = "{self.store_path}"\n'
                f'[server]\nrate_hz = {self.rate_hz:g}\nstate_file = "{self.state_path}"\nsatellite = 25544\n'
                'tune = true\ntrack = true\n'
                '[dialects]\npredict_udp = true\npredict_port = 0\n[tcp]\nenabled = true\nport = 0\n')
        if self.rot is not None and self.rig is not None:
            text += (f'[rotor]\nbackend = "rotctld"\nport = {self.rot.port}\ngeometry = "overlap-450"\n'
                     f'[radio]\nbackend = "rigctld"\nport = {self.rig.port}\nenabled = true\n')
        return text

    def __enter__(self) -> StationRig:
        if self.daemons_wanted:
            from tests.hamlib_daemons import HamlibDaemon

            self.rot = HamlibDaemon("rotctld").start()
            self.rig = HamlibDaemon("rigctld").start()
        self.system = FakeDdeSystem()
        config = parse_config(self.config_text(), str(self.workdir / "campaign.toml"))
        self.station = Station(config, SystemClock(), transport=self.system.server_transport())
        self.station.start()
        self.dde = self.system.connect("NFW32", "NFW_DATA", "campaign-watcher")
        self.dde.on_receive = self._on_dde
        self.dde.start_advise("NFW_SERVER")
        self.control = self.system.connect("NFW32", "NFW_DATA", "campaign-control")
        self.tcp_watcher = TcpWatcher(self.station.tcp.address)
        self.station.core.subscribe(self._on_tick)
        self.control.poke("NFW_SERVER", "TUNE ON")
        return self

    def __exit__(self, *exc: object) -> None:
        self.tcp_watcher.close()
        if self.station is not None:
            self.station.stop()
        for daemon in (self.rot, self.rig):
            if daemon is not None:
                daemon.kill()

    def _on_tick(self, sample) -> None:
        if sample.text:
            with self._lock:
                self.published.append(sample.text)
                self.published_total += 1

    def _on_dde(self, received) -> None:
        if received.kind == "data":
            with self._lock:
                self.dde_received.append(received.text)
                self.dde_total += 1

    # -- what the families use ---------------------------------------------------------------------------
    @property
    def core(self):
        return self.station.core

    def restore(self) -> None:
        """Back to a publishing state after a family that may have switched things off (TUNE OFF, SAT=...)."""
        for poke in ("TUNE ON", "SAT=25544", "TRACK ON"):
            try:
                self.control.poke("NFW_SERVER", poke)
            except Exception:  # noqa: BLE001 - a refusal here shows in the check that follows
                pass

    def threads_alive(self) -> list[str]:
        """Names of the station's threads that should run and do not."""
        st = self.station
        wanted = {"publisher": st.publisher._thread, "tcp": st.tcp._thread, "predict": st.predict._thread,
                  "predict-list": st.predict._lister._thread}
        for name in ("rotor", "radio", "saver"):
            worker = getattr(st, name)
            if worker is not None:
                wanted[name] = worker._thread
        return [name for name, thread in wanted.items() if thread is None or not thread.is_alive()]

    def check(self, tally: Tally, settle_s: float = 0.6) -> None:
        """Crash: a dead thread or no published string for ``settle_s``; loss: a watcher missed strings.
        What was compared is forgotten, so the campaign's own memory does not grow with the run."""
        self.restore()
        before = self.published_total
        time.sleep(settle_s)
        if self.published_total == before:
            tally.crash(f"the station published nothing for {settle_s} s")
        failures = self.station.publisher.stats.failures
        if failures:
            tally.crash(f"{failures} publish ticks failed")
        dead = self.threads_alive()
        if dead:
            tally.crash(f"threads not running: {', '.join(dead)}")
        if self.tcp_watcher.closed:
            tally.loss("the TCP WATCH client was disconnected")
        with self._lock:
            published, self.published = self.published, []
            received, self.dde_received = self.dde_received, []
            missing_dde = self.published_total - self.dde_total - self._dde_missing  # the adapter posts first
        if missing_dde > 0:
            self._dde_missing += missing_dde
            tally.loss(f"the DDE advise client missed {missing_dde} strings", missing_dde)
        time.sleep(0.3)  # the TCP loop hands strings on a moment after they are published
        lines = self.tcp_watcher.take()
        missing_tcp = sum((Counter(published) - Counter(lines)).values())
        if missing_tcp:
            tally.loss(f"the TCP WATCH client missed {missing_tcp} of {len(published)} strings", missing_tcp)
        later = Counter(lines) - Counter(published)  # published after the swap: compared next time
        keep: list[str] = []
        for line in reversed(lines):  # the newest lines are the ones published after the swap
            if later[line] > 0:
                later[line] -= 1
                keep.append(line)
        self.tcp_watcher.put_back(keep[::-1])
        tally.extra["strings published"] = int(tally.extra.get("strings published", 0)) + len(published)
        # DDE advise data is the item's value when it is posted: a poke between a tick and its post (TUNE OFF,
        # SAT=) changes it, as on Windows.  Counted, not called a loss.
        key = "DDE deliveries differing from their tick"
        tally.extra[key] = int(tally.extra.get(key, 0)) + sum((Counter(published) - Counter(received)).values())

    def files_whole(self, tally: Tally) -> None:
        """Data lost: the element store or the state file is not whole (checked after the station stops)."""
        if self.store_path.exists():
            loaded = load_element_file(self.store_path)
            if loaded.rejected:
                tally.loss(f"the element store has {len(loaded.rejected)} unreadable sets")
        if self.state_path.exists():
            state = StateFile(self.state_path).load()
            if state.satellite is None:
                tally.loss("the session state file is not readable")
