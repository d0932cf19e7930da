"""Soak: the real station (``nfwserver run --headless``) under a busy unattended load with real daemons killed.

``python -m bench soak [--minutes N] [--accelerated]`` (opt-in: it runs for as long as it is asked).  The load
of issue #44: TUNE, TRACK and Doppler tuning on at 10 Hz; a real ``rotctld`` killed every 4 minutes and a real
``rigctld`` every 6, each for 15 s; 3 Nova TCP ``WATCH`` clients; a TCP client switching ``SAT=`` every 20 s
round the ISS, AO-10, CO-55 (no radio channel) and FOX-1B; 4 web event streams reconnecting every minute;
``nfwserver watch`` beside it; the elements re-read every 3 minutes.  ``--accelerated``: 50 Hz, and the faults,
switches, reconnections and re-reads five times as often (with ``--speed X``: X times as often; at 13, two hours
hold 26 hours of the 10 Hz run's events; an outage lasts at most 30 % of its daemon's period, so that it is
up most of the time).  Every 5 s the station's RSS, threads, descriptors,
CPU and log size are read from ``/proc``; STATUS is read twice a second for the link states; every line and
frame is timed at its client.  Writes one section (the RSS slope fitted after the warm-up, the peak, feed gaps
per client, the stalls the station logged and explained, the link states against the injected outages) and a
plot, ``docs/soak-10hz.png`` or ``docs/soak-accelerated.png``.  A STATUS sample that fails is said on stderr
and counted, and the poller carries on; STATUS unanswered for more than :data:`SILENT_S` is said at once and
makes the run exit 1 after its section is written; a daemon that does not start again is said and retried.
Linux only.
"""

from __future__ import annotations

import argparse
import signal
import sys
import tempfile
import threading
import time
from pathlib import Path

from bench.soak.load import Load
from bench.soak.report import TRUTH_S, plot, section
from bench.soak.station import ROOT, Soak

SATELLITES = [25544, 14129, 27844, 43017]  # ISS, AO-10, CO-55 (no radio channel), FOX-1B
DOWN_S = 15.0  #: how long each killed daemon stays away (seconds), at most :data:`DOWN_SHARE` of its period
DOWN_SHARE = 0.3
SILENT_S = 10.0  #: STATUS answers missing this long (seconds) are said at once and fail the benchmark


def _interrupted(signum: int, frame: object) -> None:
    raise KeyboardInterrupt


def main(argv: list[str]) -> None:
    parser = argparse.ArgumentParser(prog="python -m bench soak")
    parser.add_argument("--minutes", type=float, default=30.0, help="how long to run (default 30)")
    parser.add_argument("--accelerated", action="store_true", help="50 Hz, events five times as often")
    parser.add_argument("--speed", type=float, default=None,
                        help="with --accelerated: events this many times as often as at 10 Hz (default 5)")
    parser.add_argument("--sample-s", type=float, default=5.0, help="seconds between samples of the process")
    args = parser.parse_args(argv)
    if args.speed is not None and (args.speed <= 0.0 or not args.accelerated):
        parser.error("--speed takes a number above 0, with --accelerated")
    signal.signal(signal.SIGTERM, _interrupted)  # a stopped soak still stops its station and daemons
    speed = args.speed or (5.0 if args.accelerated else 1.0)
    rate = 50.0 if args.accelerated else 10.0
    warmup_s = min(20.0, args.minutes / 2.0) * 60.0
    with tempfile.TemporaryDirectory(prefix="nfw-soak-") as work:
        soak = Soak(rate, Path(work))
        soak.start(refresh_hours=0.05 / speed)
        load = Load(soak.tcp_port, soak.web_port, SATELLITES, 20.0 / speed, 60.0 / speed)
        load.start()
        stop = threading.Event()
        schedule = {"rotctld": 240.0 / speed, "rigctld": 360.0 / speed}
        down = {daemon: min(DOWN_S, DOWN_SHARE * period) for daemon, period in schedule.items()}
        due = dict(schedule)
        faults: list[threading.Thread] = []
        ends = soak.started + args.minutes * 60.0
        next_sample = soak.started
        silent_since: float | None = None  # when the current silence of STATUS answers was first said
        silences: list[tuple[float, float]] = []  # (start, seconds) of each silence over SILENT_S, run seconds
        try:
            while time.monotonic() < ends:
                now = time.monotonic()
                silent_s = load.status_silence_s(now, soak.started)
                if silent_s > SILENT_S and silent_since is None:
                    silent_since = now - silent_s
                    print(f"  {(now - soak.started) / 60.0:5.1f} min: NO STATUS ANSWER for {silent_s:.0f} s "
                          f"(poller {'alive' if load.polling else 'DEAD'}, {load.status_failures} failed samples)",
                          file=sys.stderr)
                elif silent_s <= SILENT_S and silent_since is not None:
                    silences.append((silent_since - soak.started, now - silent_since))
                    print(f"  {(now - soak.started) / 60.0:5.1f} min: STATUS answers again after "
                          f"{now - silent_since:.0f} s", file=sys.stderr)
                    silent_since = None
                if now >= next_sample:
                    sample = soak.sample()
                    next_sample += args.sample_s
                    if len(soak.samples) % 60 == 1:
                        print(f"  {sample.at / 60.0:5.1f} min: RSS {sample.rss_mib:.1f} MiB, {sample.threads} threads, "
                              f"{sample.fds} fds", file=sys.stderr)
                for daemon, period in schedule.items():
                    if now - soak.started >= due[daemon]:
                        due[daemon] += period
                        thread = threading.Thread(target=soak.kill, args=(daemon, down[daemon], stop), daemon=True)
                        thread.start()
                        faults.append(thread)
                time.sleep(0.2)
        finally:
            stop.set()
            for thread in faults:
                thread.join(30.0)
            soak.sample()
            if silent_since is not None:
                silences.append((silent_since - soak.started, time.monotonic() - silent_since))
            load.join()
            soak.stop()
        if args.accelerated:
            title = "Soak: the real process, accelerated (50 Hz)"  # the speed is in the description
            png = ROOT / "docs" / "soak-accelerated.png"
        else:
            title = "Soak: the real process at 10 Hz"
            png = ROOT / "docs" / "soak-10hz.png"
        options = (" --accelerated" if args.accelerated else "") + (f" --speed {args.speed:g}" if args.speed else "")
        what = (f"`python -m bench soak --minutes {args.minutes:g}{options}`: "
                f"{rate:g} Hz, TUNE/TRACK/tuning on; rotctld killed every {schedule['rotctld']:.3g} s for "
                f"{down['rotctld']:.3g} s and rigctld every {schedule['rigctld']:.3g} s for {down['rigctld']:.3g} s; "
                f"3 TCP WATCH clients; SAT= every "
                f"{20.0 / speed:.3g} s round {', '.join(map(str, SATELLITES))}; 4 web streams reconnecting every "
                f"{60.0 / speed:.3g} s; `nfwserver watch`; elements re-read every {180.0 / speed:.3g} s; "
                f"{args.minutes * speed / 60.0:.3g} hours of the 10 Hz run's events.")
        drawn = plot(png, title, soak, load, warmup_s)
        print(section(title, what, soak, load, args.minutes, warmup_s, drawn, min(TRUTH_S, min(down.values()) / 2)))
        if silences:
            print(f"FAILED: STATUS went unanswered for more than {SILENT_S:g} s "
                  + ", ".join(f"from {at / 60.0:.1f} min for {length:.0f} s" for at, length in silences)
                  + f" ({load.status_failures} failed samples); the link states of that time were not checked",
                  file=sys.stderr)
            sys.exit(1)


if __name__ == "__main__":
    main(sys.argv[1:])
