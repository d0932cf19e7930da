"""The web dashboard of a real ``nfwserver run --web`` process: frame latency to N browsers, the station's CPU
and memory, with and without the floods of issue 35 (a slowloris and a header flood) running beside them.

Three processes: the station (``python -m nfwserver run --headless --web``, its own configuration in a
temporary folder, 10 Hz), the browsers (``--browsers``: N event streams read by one process, each from an
address of its own, 127.0.1.x, as browsers on other machines) and the floods (``--flood``: 64 connections
from 127.0.0.2 each trickling a header byte a second, and 16 threads each sending 99 headers of 65 KB from
127.0.0.3, reconnecting whenever the station closes them).  Latency = the wall time a frame arrived minus
its sample's instant (``now.time``: the same machine's clock).  CPU = the station's user+system time over
the window / the window; RSS from ``/proc`` (Linux).
"""

from __future__ import annotations

import json
import os
import re
import selectors
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from datetime import datetime
from pathlib import Path

from tests.waiting import wait_for

ROOT = Path(__file__).resolve().parent.parent
_TIME = re.compile(rb'"now": \{"time": "([^"]+)"')


def _config(folder: Path, port: int) -> Path:
    path = folder / "station.toml"
    path.write_text(f'[observer]\nlocation = "52.2053,0.1218,20"\n'
                    f'[elements]\nfiles = ["{ROOT / "tests" / "data" / "visual.txt"}"]\nuse_bundled = false\n'
                    '[server]\nsatellite = 25544\ntune = true\nstate_file = "none"\nrate_hz = 10\n'
                    '[satellites]\nfavourites = [25544, 694, 733, 877]\n'
                    f'[web]\nenabled = true\nport = {port}\nallow = ["127.0.0.0/8"]\n')
    return path


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


class Station:
    """``nfwserver run --headless --web`` in a process of its own."""

    def __init__(self, folder: Path) -> None:
        self.port = _free_port()
        config = _config(folder, self.port)
        env = {**os.environ, "PYTHONPATH": str(ROOT), "XDG_STATE_HOME": str(folder / "state")}  # not another's
        self.proc = subprocess.Popen([sys.executable, "-m", "nfwserver", "run", "--config", str(config), "--headless",
                                      "--log-file", str(folder / "station.log"), "--web"],
                                     cwd=folder, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        wait_for(self._answers, 60.0, "the station to answer on its web port", interval_s=0.2, tolerate=(OSError,))

    def _answers(self) -> bool:
        with socket.create_connection(("127.0.0.1", self.port), timeout=2) as sock:
            sock.sendall(b"GET /api/help HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n")
            return sock.recv(12).startswith(b"HTTP/1.0 200")

    def cpu_s(self) -> float:
        fields = Path(f"/proc/{self.proc.pid}/stat").read_text().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")

    def memory_mib(self) -> tuple[float, float]:
        """(RSS now, peak RSS) in MiB."""
        status = dict(line.split(":", 1) for line in Path(f"/proc/{self.proc.pid}/status").read_text().splitlines())
        return int(status["VmRSS"].split()[0]) / 1024, int(status["VmHWM"].split()[0]) / 1024

    def stop(self) -> None:
        self.proc.terminate()
        self.proc.wait(30)


def browsers_process(port: int, n: int, seconds: float) -> None:
    """Child: ``n`` event streams for ``seconds``; prints {"latency_ms": [...], "frames": [per stream]}."""
    sel = selectors.DefaultSelector()
    buffers, frames, latency = [b""] * n, [0] * n, []
    for i in range(n):  # each browser from an address of its own, as from machines of their own
        sock = socket.create_connection(("127.0.0.1", port), source_address=(f"127.0.1.{i + 1}", 0))
        sock.sendall(b"GET /api/stream HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
        sock.setblocking(False)
        sel.register(sock, selectors.EVENT_READ, i)
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        for key, _ in sel.select(0.05):
            data = key.fileobj.recv(1 << 20)  # type: ignore[union-attr]
            arrived = time.time()
            buffers[key.data] += data
            *messages, buffers[key.data] = buffers[key.data].split(b"\n\n")
            for message in messages:
                found = _TIME.search(message)
                if message.startswith(b"event: state") and found:
                    frames[key.data] += 1
                    sent = datetime.fromisoformat(found.group(1).decode().replace("Z", "+00:00")).timestamp()
                    latency.append((arrived - sent) * 1e3)
    print(json.dumps({"latency_ms": latency, "frames": frames}), flush=True)


def flood_process(port: int) -> None:
    """Child: the slowloris and the header flood, until stdin closes."""
    stop = threading.Event()
    counts = {"slow": 0, "big": 0}

    def slowloris() -> None:
        socks: list[socket.socket | None] = [None] * 64
        while not stop.is_set():
            for i, sock in enumerate(socks):
                try:
                    if sock is None:
                        sock = socks[i] = socket.create_connection(("127.0.0.1", port), timeout=2,
                                                                   source_address=("127.0.0.2", 0))
                        sock.sendall(b"GET /api/help HTTP/1.1\r\nHost: 127.0.0.1\r\nX-a: ")
                        counts["slow"] += 1
                    sock.send(b"a")
                except OSError:
                    if sock is not None:
                        sock.close()
                    socks[i] = None
            stop.wait(1.0)

    head = b"GET /api/help HTTP/1.1\r\nHost: 127.0.0.1\r\n" + b"".join(
        b"X-%d: %s\r\n" % (i, b"a" * 65000) for i in range(99)) + b"\r\n"

    def big_headers() -> None:
        while not stop.is_set():
            try:
                with socket.create_connection(("127.0.0.1", port), timeout=5,
                                              source_address=("127.0.0.3", 0)) as sock:
                    counts["big"] += 1
                    sock.sendall(head)
                    sock.recv(100)
            except OSError:
                pass

    threads = [threading.Thread(target=slowloris, daemon=True)]
    threads += [threading.Thread(target=big_headers, daemon=True) for _ in range(16)]
    for thread in threads:
        thread.start()
    print("ready", flush=True)
    sys.stdin.readline()
    stop.set()
    print(json.dumps(counts), flush=True)


def _child(*args: str, stdin: int | None = None) -> subprocess.Popen[str]:
    return subprocess.Popen([sys.executable, "-m", "bench.web_process", *args], cwd=ROOT, stdin=stdin,
                            stdout=subprocess.PIPE, text=True, env={**os.environ, "PYTHONPATH": str(ROOT)})


def measure(station: Station, n: int, seconds: float) -> dict[str, float]:
    """One window of ``seconds`` with ``n`` browsers."""
    cpu0, t0 = station.cpu_s(), time.monotonic()
    child = _child("--browsers", str(station.port), str(n), str(seconds))
    out, _ = child.communicate(timeout=seconds + 60)
    cpu = (station.cpu_s() - cpu0) / (time.monotonic() - t0)
    result = json.loads(out)
    latency = sorted(result["latency_ms"])
    rss, peak = station.memory_mib()
    p99 = latency[min(len(latency) - 1, int(0.99 * len(latency)))] if latency else float("nan")
    return {"p50": statistics.median(latency) if latency else float("nan"), "p99": p99,
            "fps": min(result["frames"]) / seconds, "cpu": cpu * 100, "rss": rss, "peak": peak}


def main(seconds: float = 15.0) -> None:
    """Print the section's table: 1/10/50 browsers, without and with the floods."""
    print("Against the real process: the station is `nfwserver run --headless --web` at 10 Hz in a process of its "
          "own; the browsers, N event streams each from an address of its own (127.0.1.x, as from other machines), "
          "are read by another; the floods, from a third, are issue 35's: 64 connections from 127.0.0.2 each "
          "trickling a header byte a second, and 16 threads each sending 99 headers of 65 KB from 127.0.0.3, "
          "reconnecting whenever the station closes them. Frame latency = the wall time a frame arrived minus its "
          "sample's instant (the same machine's clock). Station CPU = its user+system time over the window / the "
          f"window (100% = one core); RSS from /proc. Each window {seconds:g} s; load average at start "
          f"{os.getloadavg()[0]:.1f} (the machine is shared).\n")
    print("| browsers | floods | frame latency p50 | p99 | frames/s the slowest browser got | station CPU | RSS "
          "(peak) |")
    print("|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as folder:
        station = Station(Path(folder))
        try:
            idle = station.memory_mib()[0]
            print(f"| 0 | no | - | - | - | - | {idle:.1f} MiB |")
            for flooding in (False, True):
                flood = _child("--flood", str(station.port), stdin=subprocess.PIPE) if flooding else None
                if flood is not None:
                    assert flood.stdout is not None and flood.stdout.readline().strip() == "ready"
                    time.sleep(3.0)  # the floods at full strength before the window
                for n in (1, 10, 50):
                    m = measure(station, n, seconds)
                    print(f"| {n} | {'yes' if flooding else 'no'} | {m['p50']:.1f} ms | {m['p99']:.1f} ms | "
                          f"{m['fps']:.1f} | {m['cpu']:.0f}% | {m['rss']:.1f} MiB ({m['peak']:.1f}) |")
                if flood is not None:
                    out, _ = flood.communicate("\n", timeout=30)
                    counts = json.loads(out)
                    print(f"| | | floods: {counts['slow']} slow connections opened, {counts['big']} header floods "
                          "sent | | | | |")
        finally:
            station.stop()
    print()


if __name__ == "__main__":
    if sys.argv[1:2] == ["--browsers"]:
        browsers_process(int(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4]))
    elif sys.argv[1:2] == ["--flood"]:
        flood_process(int(sys.argv[2]))
    else:
        main(float(sys.argv[1]) if len(sys.argv) > 1 else 15.0)
