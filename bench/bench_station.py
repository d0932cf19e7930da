"""The running station as a user runs it: ``nfwserver run --headless`` with TCP and web on, measured from outside.

The station is the real process (``python -m nfwserver run --headless --config FILE``: ISS selected, TUNE ON,
the default 5 Hz).  Its clients run in other processes, as real clients do: 1, 10 and 100 TCP ``WATCH`` clients,
then 1, 10 and 50 event streams (``GET /api/stream``, what a browser's page holds open; each from an address of its
own, 127.0.1.x, as browsers on other machines: the web server serves at most 16 connections from one
address).  For each, over :data:`SECONDS` seconds after a second of warm-up:

- delivery latency: from the tick's instant (the time its web frame carries, in milliseconds) to the arrival of
  its line (TCP) or frame (web) at each client, p50 and p99 over every client and tick.  A TCP line is matched
  to its tick by its Nova string, through one more event stream read by the TCP clients' process (strings seen
  twice are left out);
- the station's CPU (% of one core: user + system time from ``/proc/PID/stat`` over the interval) and its
  resident memory (``VmRSS`` from ``/proc/PID/status``, the largest sampled every half second);
- lines or frames lost: ticks some client did not get.

First the idle station (web on, no client).  Linux only (``/proc``).
"""

from __future__ import annotations

import json
import os
import selectors
import socket
import subprocess
import sys
import tempfile
import time
from datetime import datetime
from pathlib import Path

import numpy as np

from tests.waiting import wait_for

ROOT = Path(__file__).resolve().parent.parent
SECONDS = float(os.environ.get("NFW_BENCH_STATION_S", "15"))
RATE_HZ = 5


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _stream(host: str, port: int, source: str | None = None) -> socket.socket:
    """An event stream of the page, from the address ``source`` (a browser of its own: the web server serves at
    most 16 connections from one address)."""
    sock = socket.create_connection((host, port), source_address=(source, 0) if source else None)
    sock.sendall(f"GET /api/stream HTTP/1.0\r\nHost: {host}:{port}\r\n\r\n".encode())
    sock.setblocking(False)
    return sock


def _frames(buffer: bytes) -> tuple[list[dict[str, object]], bytes]:
    """The ``state`` frames complete in ``buffer`` (their JSON's ``now``), and what is left of it."""
    *messages, rest = buffer.split(b"\n\n")
    frames = []
    for message in messages:
        if message.startswith(b"event: state\ndata: "):
            now = json.loads(message[len(b"event: state\ndata: "):]).get("now") or {}
            frames.append(now)
    return frames, rest


def _epoch(iso: str) -> float:
    return datetime.fromisoformat(iso.replace("Z", "+00:00")).timestamp()


def client_process(kind: str, host: str, tcp_port: int, web_port: int, n: int) -> None:
    """Child: ``n`` clients of ``kind`` (``tcp`` or ``web``), plus a reference event stream for ``tcp``.  Prints
    "ready"; records from a "start" line on stdin until a "stop" line, then prints the latencies (ms) and each
    client's count of ticks received, as JSON."""
    socks = []
    for i in range(n):
        if kind == "tcp":
            sock = socket.create_connection((host, tcp_port))
            sock.sendall(b"WATCH\r\n")
            sock.setblocking(False)
        else:
            sock = _stream(host, web_port, f"127.0.1.{i + 1}")  # each browser from an address of its own
        socks.append(sock)
    reference = _stream(host, web_port) if kind == "tcp" else None
    sel = selectors.DefaultSelector()
    for i, sock in enumerate(socks):
        sel.register(sock, selectors.EVENT_READ, i)
    if reference is not None:
        sel.register(reference, selectors.EVENT_READ, -2)
    sel.register(sys.stdin, selectors.EVENT_READ, -1)
    buffers = [b""] * (n + 1)
    skip = [2] * n  # a TCP client's greeting and WATCH's OK
    recording = False
    tick_of: dict[str, float] = {}  # Nova string -> its tick's instant (s since 1970)
    seen_twice: set[str] = set()
    arrivals: list[list[tuple[str, float]]] = [[] for _ in range(n)]  # (string or tick time, arrival)
    print("ready", flush=True)
    while True:
        for key, _ in sel.select(0.05):
            if key.data == -1:
                word = sys.stdin.readline().strip()
                if word == "start":
                    recording = True
                    continue
                latencies = []
                for per_client in arrivals:
                    for label, when in per_client:
                        tick = tick_of.get(label) if kind == "tcp" else _epoch(label)
                        if tick is not None and label not in seen_twice:
                            latencies.append((when - tick) * 1e3)
                print(json.dumps({"latency_ms": latencies, "counts": [len(a) for a in arrivals]}), flush=True)
                return
            data = key.fileobj.recv(1 << 20)
            now = time.time()
            slot = n if key.data == -2 else key.data
            buffers[slot] += data
            if key.data == -2 or kind == "web":
                frames, buffers[slot] = _frames(buffers[slot])
                for frame in frames:
                    if key.data == -2 and isinstance(frame.get("nova"), str) and isinstance(frame.get("time"), str):
                        nova = str(frame["nova"])
                        if nova in tick_of:
                            seen_twice.add(nova)
                        tick_of[nova] = _epoch(str(frame["time"]))
                    elif key.data >= 0 and recording and isinstance(frame.get("time"), str):
                        arrivals[key.data].append((str(frame["time"]), now))
                continue
            *lines, buffers[slot] = buffers[slot].split(b"\n")
            for line in lines:
                if skip[key.data]:
                    skip[key.data] -= 1
                elif recording:
                    arrivals[key.data].append((line.decode().rstrip("\r"), now))


def _cpu_s(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")  # utime + stime


def _rss_mib(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024.0
    return 0.0


def _measure(pid: int, seconds: float) -> tuple[float, float]:
    """The station's CPU (% of a core) over ``seconds``, and its largest resident set (MiB) meanwhile."""
    cpu0, t0, rss = _cpu_s(pid), time.monotonic(), _rss_mib(pid)
    while time.monotonic() - t0 < seconds:
        time.sleep(0.5)
        rss = max(rss, _rss_mib(pid))
    return (_cpu_s(pid) - cpu0) / (time.monotonic() - t0) * 100.0, rss


class Station:
    """``nfwserver run --headless`` on free TCP and web ports, ISS selected, TUNE ON, in a temporary folder."""

    def __init__(self, folder: Path) -> None:
        self.tcp, self.web = _free_port(), _free_port()
        config = folder / "station.toml"
        config.write_text(
            '[observer]\nlocation = "52.2,0.12,20"\n'
            f'[elements]\nfiles = ["{ROOT / "tests" / "data" / "visual.txt"}"]\nuse_bundled = false\nstore = "none"\n'
            f'[server]\nsatellite = 25544\ntune = true\nstate_file = "none"\nrate_hz = {RATE_HZ}\n'
            f'[tcp]\nenabled = true\nport = {self.tcp}\nmax_clients = 512\nmax_per_address = 512\n'
            f'[web]\nenabled = true\nport = {self.web}\nallow = ["127.0.0.0/8"]\n')
        self.proc = subprocess.Popen([sys.executable, "-m", "nfwserver", "run", "--headless", "--config", str(config),
                                      "--log-file", str(folder / "station.log")], cwd=ROOT,
                                     stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        wait_for(self._serving, 60.0, "the station to open its web and TCP ports", interval_s=0.1)

    def _serving(self) -> bool:
        if self.proc.poll() is not None:
            why = self.proc.stderr.read().decode() if self.proc.stderr else ""
            raise RuntimeError(f"the station exited: {why}")
        try:
            socket.create_connection(("127.0.0.1", self.web), timeout=1).close()
            socket.create_connection(("127.0.0.1", self.tcp), timeout=1).close()
        except OSError:
            return False
        return True

    def stop(self) -> None:
        self.proc.terminate()
        self.proc.wait(30)


def _scenario(station: Station, kind: str, n: int) -> tuple[float, float, float, float, int]:
    """Latency p50/p99 (ms), station CPU (%) and RSS (MiB), ticks lost, with ``n`` clients of ``kind``."""
    child = subprocess.Popen([sys.executable, "-m", "bench.bench_station", "--clients", kind, "127.0.0.1",
                              str(station.tcp), str(station.web), str(n)], cwd=ROOT, stdin=subprocess.PIPE,
                             stdout=subprocess.PIPE, text=True)
    assert child.stdin is not None and child.stdout is not None
    assert child.stdout.readline().strip() == "ready"
    time.sleep(1.0)  # warm-up
    child.stdin.write("start\n")
    child.stdin.flush()
    cpu, rss = _measure(station.proc.pid, SECONDS)
    child.stdin.write("stop\n")
    child.stdin.flush()
    result = json.loads(child.stdout.readline())
    child.wait(10)
    latency = np.array(result["latency_ms"]) if result["latency_ms"] else np.array([np.nan])
    expected = round(SECONDS * RATE_HZ)
    lost = sum(max(0, expected - 1 - count) for count in result["counts"])  # one tick may straddle start or stop
    return float(np.percentile(latency, 50)), float(np.percentile(latency, 99)), cpu, rss, lost


def main() -> None:
    if not Path("/proc/self/stat").exists():
        print("bench_station needs /proc (Linux)", file=sys.stderr)
        return
    load_before = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as folder:
        station = Station(Path(folder))
        try:
            time.sleep(2.0)
            idle_cpu, idle_rss = _measure(station.proc.pid, SECONDS)
            rows = []
            for kind, counts in (("tcp", (1, 10, 100)), ("web", (1, 10, 50))):
                for n in counts:
                    rows.append((kind, n, *_scenario(station, kind, n)))
                    print(f"  {kind} x {n}: {rows[-1][2:]}", file=sys.stderr)
        finally:
            station.stop()
    load_after = os.getloadavg()[0]
    print("## The running station (`nfwserver run --headless`, TCP and web on)\n")
    print(f"The real station process at {RATE_HZ} Hz (ISS selected, TUNE ON), its clients in other processes on "
          f"loopback; each row {SECONDS:g} s after a second of warm-up. Latency: from the tick's instant (the time "
          "its web frame carries, truncated to the millisecond, so up to 1 ms high) to the arrival at each client "
          "of its TCP line (matched by its Nova string through one more event stream) or its event-stream frame, "
          "p50/p99 over every client and tick. CPU: the station's user + system time from /proc over the interval, "
          "in % of one core; RSS: its largest VmRSS. Lost: ticks some client did not get. "
          f"Load average (1 min) {load_before:.1f} at the start, {load_after:.1f} at the end, "
          f"{os.cpu_count()} cores shared with other work.\n")
    print("| clients | latency p50 | latency p99 | station CPU | station RSS | lost |")
    print("|---|---|---|---|---|---|")
    print(f"| none (idle, web on) | - | - | {idle_cpu:.1f} % | {idle_rss:.1f} MiB | - |")
    for kind, n, p50, p99, cpu, rss, lost in rows:
        label = f"{n} TCP WATCH" if kind == "tcp" else f"{n} event stream{'s' if n > 1 else ''}"
        print(f"| {label} | {p50:.2f} ms | {p99:.2f} ms | {cpu:.1f} % | {rss:.1f} MiB | {lost} |")
    print()


if __name__ == "__main__":
    if sys.argv[1:2] == ["--clients"]:
        client_process(sys.argv[2], sys.argv[3], int(sys.argv[4]), int(sys.argv[5]), int(sys.argv[6]))
    else:
        main()
