"""Issue 42's attacks on the web dashboard, against a real ``nfwserver run --headless --web`` process.

The station runs in a process of its own with control on (a strong token) and ``allow = ["127.0.0.0/8"]``, so
127.0.0.2 to 127.0.0.10 play other machines; the attacker and the operator are this process (the slow
connections on a thread of their own, each reconnecting whenever the station closes it, as an attacker
would).  Each row prints what the operator saw: answers to ``GET /api/help`` from 127.0.0.1 during the
attack, frames on its event streams, log lines and events written, the old token after ``nfwserver config
set`` returned.  ``python -m bench web`` prints the table (``bench/bench_web.py``).
"""

from __future__ import annotations

import json
import os
import socket
import statistics
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from tempfile import TemporaryDirectory

from bench.web_process import ROOT, Station, _free_port
from nfwserver.config.tokens import new_token
from tests.waiting import wait_for

OTHERS = tuple(f"127.0.0.{n}" for n in range(2, 10))
WEAK = ("qwerty123", "1q2w3e4r5t", "abcd1234", "a1b2c3d4", "asdfghjkl", "01234567890")
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}


class ControlledStation(Station):
    """:class:`~bench.web_process.Station` with web control on and the token :attr:`token`."""

    def __init__(self, folder: Path) -> None:  # noqa: D107 - the parent's start, another configuration
        self.port, self.token, self.folder = _free_port(), new_token(), folder
        #: a state folder of its own: another station of this user (a test run beside) is not this one
        self.env = {**ENV, "XDG_STATE_HOME": str(folder / "state")}
        self.config = folder / "station.toml"
        self.config.write_text(
            f'[observer]\nlocation = "52.2053,0.1218,20"\n'
            f'[elements]\nfiles = ["{ROOT / "tests" / "data" / "visual.txt"}"]\nuse_bundled = false\n'
            '[server]\nsatellite = 25544\ntune = true\nstate_file = "none"\nrate_hz = 10\n'
            f'[web]\nenabled = true\nport = {self.port}\nallow = ["127.0.0.0/8"]\ncontrol = true\n'
            f'token = "{self.token}"\n')
        self.log = folder / "station.log"
        self.proc = subprocess.Popen([sys.executable, "-m", "nfwserver", "run", "--config", str(self.config),
                                      "--headless", "--log-file", str(self.log)], cwd=folder, env=self.env,
                                     stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        wait_for(self._answers, 60.0, "the station to answer on its web port", interval_s=0.2, tolerate=(OSError,))

    def exchange(self, data: bytes, source: str = "127.0.0.1", timeout_s: float = 10.0) -> bytes:
        with socket.create_connection(("127.0.0.1", self.port), timeout=timeout_s,
                                      source_address=(source, 0)) as sock:
            sock.sendall(data)
            chunks = []
            while True:
                try:
                    chunk = sock.recv(65536)
                except OSError:
                    break
                if not chunk:
                    break
                chunks.append(chunk)
            return b"".join(chunks)

    def command(self, token: str, command: str = "TUNE ON", source: str = "127.0.0.1",
                headers: str = "") -> int:
        body = json.dumps({"command": command, "token": token}).encode()
        head = (f"POST /api/command HTTP/1.0\r\nHost: 127.0.0.1:{self.port}\r\nContent-Type: application/json\r\n"
                f"Content-Length: {len(body)}\r\n{headers}\r\n").encode()
        return status(self.exchange(head + body, source))

    def config_set(self, key: str, value: str) -> int:
        return subprocess.run([sys.executable, "-m", "nfwserver", "config", "set", key, value, "--config",
                               str(self.config)], env=self.env, capture_output=True, check=False).returncode


def status(reply: bytes) -> int:
    return int(reply.split(b" ", 2)[1]) if reply.startswith(b"HTTP/") else 0


GET_HELP = b"GET /api/help HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n"


@contextmanager
def slow_heads(port: int, sources: tuple[str, ...], per_source: int, every_s: float = 2.0) -> Iterator[dict[str, int]]:
    """``per_source`` connections from each of ``sources``, each sending a header byte every ``every_s``,
    reopened whenever the station closes one; yields the counts (opened, closed by the station)."""
    stop = threading.Event()
    counts = {"opened": 0, "closed": 0}
    socks: list[socket.socket | None] = [None] * (len(sources) * per_source)

    def run() -> None:
        while not stop.is_set():
            for i, sock in enumerate(socks):
                try:
                    if sock is None:
                        sock = socks[i] = socket.create_connection(("127.0.0.1", port), timeout=2,
                                                                   source_address=(sources[i // per_source], 0))
                        sock.sendall(b"GET /api/help HTTP/1.1\r\nHost: 127.0.0.1\r\nX-a: ")
                        counts["opened"] += 1
                    sock.send(b"a")
                except OSError:
                    counts["closed"] += sock is not None
                    if sock is not None:
                        sock.close()
                    socks[i] = None
            stop.wait(every_s)

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    try:
        wait_for(lambda: counts["opened"] >= len(socks), 30.0, "the slow connections")
        time.sleep(2 * every_s)  # a round of reconnections, at full strength
        yield counts
    finally:
        stop.set()
        thread.join(10)
        for sock in socks:
            if sock is not None:
                sock.close()


def operator_checks(station: ControlledStation, n: int = 20, source: str = "127.0.0.1") -> str:
    """``n`` requests of the operator, 0.25 s apart: how many answered 200, and how fast."""
    times, ok = [], 0
    for _ in range(n):
        began = time.monotonic()
        try:
            ok += status(station.exchange(GET_HELP, source)) == 200
        except OSError:
            pass
        times.append((time.monotonic() - began) * 1e3)
        time.sleep(0.25)
    return f"{ok} of {n} answered 200 (p50 {statistics.median(times):.1f} ms, max {max(times):.1f} ms)"


def streams_during_flood(station: ControlledStation, seconds: float = 10.0) -> str:
    """Two event streams of the operator while 256 slow connections of others churn."""
    streams = []
    for _ in range(2):
        sock = socket.create_connection(("127.0.0.1", station.port), timeout=5, source_address=("127.0.0.1", 0))
        sock.sendall(b"GET /api/stream HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n")
        streams.append(sock)
    frames, closed = [0, 0], [False, False]
    with slow_heads(station.port, OTHERS, 32) as counts:
        for sock in streams:  # what came while the attack built up
            sock.settimeout(0.2)
            try:
                while sock.recv(1 << 20):
                    pass
            except TimeoutError:
                pass
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            for i, sock in enumerate(streams):
                sock.settimeout(0.05)
                try:
                    data = sock.recv(1 << 20)
                except TimeoutError:
                    continue
                closed[i] = closed[i] or not data
                frames[i] += data.count(b"event: state")
        churn = counts["closed"]
    for sock in streams:
        sock.close()
    return (f"{sum(closed)} of 2 closed; {min(frames)} frames to the slower in {seconds:g} s "
            f"({min(frames) / seconds:.1f}/s) while the station closed {churn} slow connections of others")


def log_lines(station: ControlledStation) -> int:
    return len(station.log.read_text(errors="replace").splitlines())


def refusal_flood(station: ControlledStation, source: str = "127.0.0.11") -> str:
    before = station.log.read_text(errors="replace").count(f"from {source} refused")
    for n in range(600):
        station.command("x", source=source, headers=f"Origin: http://evil{n}.example\r\n")
    time.sleep(0.5)
    lines = station.log.read_text(errors="replace").count(f"from {source} refused") - before
    state = json.loads(station.exchange(b"GET /api/state HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n").split(b"\r\n\r\n", 1)[1])
    events = sum(1 for e in state["log"] if e.get("client") == f"web {source}")
    return f"{lines} log line(s), {events} of the page's last {len(state['log'])} events"


def token_changes(station: ControlledStation, rounds: int = 5) -> str:
    refused, after_ms = 0, []
    for _ in range(rounds):
        old, fresh = station.token, new_token()
        assert station.config_set("web.token", fresh) == 0
        returned = time.monotonic()
        code = station.command(old)
        after_ms.append((time.monotonic() - returned) * 1e3)
        refused += code == 403
        station.token = fresh
        assert station.command(fresh) == 200
    assert station.config_set("web.control", "false") == 0
    off = station.command(station.token) == 403
    assert station.config_set("web.control", "true") == 0
    on = station.command(station.token) == 200
    return (f"old token refused on the first request after `config set` returned: {refused} of {rounds} "
            f"(that request {statistics.median(after_ms):.1f} ms p50); control off: {'refused' if off else 'TAKEN'}, "
            f"on again: {'taken' if on else 'REFUSED'}")


def weak_tokens(station: ControlledStation) -> str:
    before = station.config.read_bytes()
    refused = sum(station.config_set("web.token", token) != 0 for token in WEAK)
    same = station.config.read_bytes() == before
    return f"{refused} of {len(WEAK)} refused by `config set` (file {'unchanged' if same else 'CHANGED'})"


ERRORS = (b"OPTIONS /api/command HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n",
          b"GET /api/help HTTP/1.1\r\nHost: 127.0.0.1\r\n" + b"X-A: b\r\n" * 150 + b"\r\n",
          b"BREW /pot HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n", b"GET /api/state\r\n", b"hello there you\r\n\r\n",
          b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nX: " + b"a" * 40000 + b"\r\n\r\n",
          b"GET /api/state HTTP/1.1\r\nHost: evil.example\r\n\r\n", b"GET /nothing HTTP/1.0\r\n\r\n",
          b"POST /api/command HTTP/1.0\r\nHost: 127.0.0.1\r\nContent-Type: text/plain\r\nContent-Length: 2\r\n\r\n{}")


def error_headers(station: ControlledStation) -> str:
    codes, covered = [], 0
    for request in ERRORS:
        reply = station.exchange(request)
        head = reply.split(b"\r\n\r\n", 1)[0].lower()
        codes.append(status(reply))
        covered += b"content-security-policy: default-src 'self'" in head and b"x-content-type-options: nosniff" \
            in head and b"content-type: application/json" in head
    return f"{covered} of {len(ERRORS)} with CSP, nosniff and a JSON body ({', '.join(map(str, sorted(codes)))})"


HOSTS = ("localhost.evil.example", "127.0.0.1.evil.example", "localhost:8091.evil.example", "[::1].evil.example",
         "localhostevil.example")


def host_prefixes(station: ControlledStation) -> str:
    refused = sum(status(station.exchange(f"GET /api/state HTTP/1.1\r\nHost: {host}\r\n\r\n".encode())) == 421
                  for host in HOSTS)
    return f"{refused} of {len(HOSTS)} answered 421"


def rows() -> list[tuple[str, str, str]]:
    """(attack, before: issue 42's figure on 0b1f0e5's parent, now: this run's)."""
    with TemporaryDirectory() as folder:
        station = ControlledStation(Path(folder))
        try:
            out = []
            lines = log_lines(station)
            with slow_heads(station.port, OTHERS, 16):
                out.append(("16 slow heads from each of 127.0.0.2-.9 (128), reopened when closed; the operator "
                            "from 127.0.0.1", "503 on 23 of 23", operator_checks(station)))
                out.append(("... and a phone from 127.0.0.10", "503", operator_checks(station, 5, "127.0.0.10")))
            with slow_heads(station.port, ("127.0.0.1",), 16):
                out.append(("16 slow heads from 127.0.0.1 itself", "503 on 12 of 12", operator_checks(station)))
            out.append(("log lines the station wrote during the two attacks above", "-",
                        f"{log_lines(station) - lines}"))
            out.append(("2 event streams of the operator, 32 slow heads from each of 127.0.0.2-.9 (256)",
                        "-", streams_during_flood(station)))
            out.append(("600 refused POSTs from 127.0.0.11, each with another Origin", "600 log lines, 196 of the "
                        "last 200 events", refusal_flood(station)))
            out.append(("`config set web.token NEW`, then the old token at once; `web.control false`",
                        "old token worked 2.07 s after", token_changes(station)))
            out.append((f"`config set web.token` {', '.join(WEAK)}", "all 6 taken", weak_tokens(station)))
            out.append(("error answers: OPTIONS, 150 headers, BREW, HTTP/0.9, garbage, 40 KB head, wrong Host, "
                        "404, text/plain command", "501 and 431 as HTML without CSP or nosniff",
                        error_headers(station)))
            out.append((f"Host {', '.join(HOSTS)}", "a prefix check passed every test",
                        host_prefixes(station)))
            return out
        finally:
            station.stop()


def main() -> None:
    print("Issue 42's attacks on a real `nfwserver run --headless` (web on, control on with a strong token, allow "
          "127.0.0.0/8 so that 127.0.0.2-.10 play other machines); the attacker's slow connections send a header "
          "byte every 2 s and are reopened whenever the station closes them (`bench/campaign/web_attacks.py`). "
          f"Load average at start {os.getloadavg()[0]:.1f}.\n")
    print("| attack | before (issue 42) | now |")
    print("|---|---|---|")
    for attack, before, now in rows():
        print(f"| {attack} | {before} | {now} |")
    print()


if __name__ == "__main__":
    main()
