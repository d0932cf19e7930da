"""The real-time run: a whole station at 50 Hz on the system clock for minutes, with light traffic on every
listener once a second, sampling this process's resident set size (RSS) as it goes.

Each second: a PREDICT ``GET_SAT`` over UDP, a TCP ``STATUS`` and ``SUMMARY``, a DDE request, and every
tenth second a switch to another satellite poked over DDE and back.  Every ten seconds the rig's check runs (the
station still publishing, no dead thread, the watchers missing nothing) and RSS is sampled.
"""

from __future__ import annotations

import resource
import socket
import time
from pathlib import Path

from bench.campaign.station_rig import GREETING, StationRig
from bench.campaign.tally import Tally


def rss_mib() -> float:
    """Resident set size of this process now (MiB); the peak where /proc is missing."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _ask(sock: socket.socket, line: bytes, buffer: bytearray) -> bool:
    sock.sendall(line + b"\r\n")
    deadline = time.monotonic() + 3.0
    while b"\r\n" not in buffer and time.monotonic() < deadline:
        buffer += sock.recv(65536)
    if b"\r\n" not in buffer:
        return False
    del buffer[: buffer.index(b"\r\n") + 2]
    return True


def run_realtime(tally: Tally, seconds: float, workdir: Path, sample_every_s: float = 10.0) -> None:
    with StationRig(workdir / "realtime", rate_hz=50.0) as rig:
        udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        udp.settimeout(3.0)
        tcp = socket.create_connection(rig.station.tcp.address, timeout=5.0)
        buffer = bytearray()
        while GREETING not in buffer:
            buffer += tcp.recv(4096)
        del buffer[: buffer.index(GREETING) + len(GREETING)]
        other = next(s.catalog_number for s in rig.station.catalog if s.catalog_number != 25544)
        samples = [(0.0, rss_mib())]
        started = time.monotonic()
        next_sample = started + sample_every_s
        second = 0
        while time.monotonic() - started < seconds:
            second += 1
            tally.tried += 1
            udp.sendto(b"GET_SAT 25544", rig.station.predict.address)
            try:
                if not udp.recv(65536).startswith(b"ISS"):
                    tally.loss("GET_SAT did not answer the ISS")
            except TimeoutError:
                tally.loss("GET_SAT unanswered for 3 s")
            for line in (b"STATUS", b"SUMMARY"):
                if not _ask(tcp, line, buffer):
                    tally.loss(f"TCP {line.decode()} unanswered for 3 s")
            rig.control.request("NFW_SERVER")
            if second % 10 == 0:
                rig.control.poke("NFW_SERVER", f"SAT={other}")
                rig.control.poke("NFW_SERVER", "SAT=25544")
            now = time.monotonic()
            if now >= next_sample:
                rig.check(tally, settle_s=0.1)
                samples.append((now - started, rss_mib()))
                next_sample += sample_every_s
            time.sleep(max(0.0, started + second - time.monotonic()))
        rig.check(tally)
        samples.append((time.monotonic() - started, rss_mib()))
        stats = rig.station.publisher.stats
        lateness = stats.lateness
        udp.close()
        tcp.close()
    first_minute = next((rss for t, rss in samples if t >= 60.0), samples[-1][1])
    tally.extra.update({
        "duration": f"{samples[-1][0]:.0f} s", "ticks": stats.ticks, "ticks skipped": stats.skipped,
        "tick failures": stats.failures,
        "lateness p99 / max": f"{lateness.quantile(0.99) * 1e3:.1f} / {lateness.max_s * 1e3:.1f} ms"
        if lateness.total else "-",
        "RSS at start / after 1 min / at end": f"{samples[0][1]:.1f} / {first_minute:.1f} / {samples[-1][1]:.1f} MiB",
        "RSS growth start->end / 1 min->end": f"{samples[-1][1] - samples[0][1]:+.1f} / "
                                               f"{samples[-1][1] - first_minute:+.1f} MiB",
    })
    tally.extra["rss samples"] = samples
