"""The soak's Markdown section and plot: RSS slope after warm-up, peak, threads, descriptors, CPU, log growth,
feed gaps per client, stalls the station logged, and the link states STATUS gave against the injected outages."""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from bench.soak.load import GAP_S, FeedTimes, LinkSample, Load
from bench.soak.station import Outage, Sample, Soak

#: how long (seconds) after a kill or a restart the STATUS line may take to say so before it counts as untrue
TRUTH_S = 5.0


@dataclass(frozen=True)
class OutageSeen:
    """One outage as STATUS showed it: seconds from the kill to ``unreachable`` and from the restart to its end
    (None: never within the outage / the run), and the duration the log gave it."""

    outage: Outage
    noticed_s: float | None
    healed_s: float | None
    logged_s: float | None


def slope_mib_h(samples: list[Sample], after_s: float) -> float:
    """Least-squares RSS slope (MiB per hour) over the samples after ``after_s`` seconds."""
    late = [s for s in samples if s.at >= after_s]
    if len(late) < 3:
        return float("nan")
    fit = np.polyfit([s.at / 3600.0 for s in late], [s.rss_mib for s in late], 1)
    return float(fit[0])


def longest_silence(load: Load, started: float, ended: float) -> tuple[float, float]:
    """The longest time (seconds) without a STATUS answer between ``started`` and ``ended`` (monotonic
    seconds), the start and the end of the run included, and when it began (seconds into the run)."""
    times = [started] + [s.at for s in load.links] + [ended]
    length, at = max((b - a, a) for a, b in zip(times, times[1:]))
    return length, at - started


def _word(sample: LinkSample, daemon: str) -> str:
    return sample.rotor if daemon == "rotctld" else sample.radio


def outages_seen(soak: Soak, load: Load, log_text: str) -> list[OutageSeen]:
    """Each outage against the STATUS answers around it and the log's "recovered after" lines, in order."""
    recovered = {name: [float(x) for x in re.findall(rf"{name}: recovered after ([\d.]+) s", log_text)]
                 for name in ("rotctld", "rigctld")}
    seen = []
    for outage in soak.outages:
        up = outage.up if outage.up is not None else float("inf")
        noticed = next((s.at - outage.down for s in load.links
                        if outage.down <= s.at <= up and _word(s, outage.daemon) == "unreachable"), None)
        healed = next((s.at - up for s in load.links if s.at >= up and _word(s, outage.daemon) != "unreachable"
                       and outage.daemon not in s.faults), None)
        durations = recovered[outage.daemon]
        seen.append(OutageSeen(outage, noticed, healed, durations.pop(0) if durations else None))
    return seen


def _gaps(feeds: list[FeedTimes]) -> str:
    return ", ".join(f"{f.name} {f.longest_s:.2f} s ({len(f.gaps)})" for f in feeds)


def _fmt(value: float | None) -> str:
    return "-" if value is None else f"{value:.1f}"


def section(title: str, what: str, soak: Soak, load: Load, minutes: float, warmup_s: float, plot: Path | None,
            truth_s: float = TRUTH_S) -> str:
    """The Markdown section of one run; an outage counts as shown late, or logged with a wrong length, beyond
    ``truth_s`` seconds (less than :data:`TRUTH_S` when the outages are short)."""
    samples = soak.samples
    log_text = "".join(p.read_text("utf-8", "replace") for p in sorted(soak.work.glob("nfwserver.log*")))
    stalls = re.findall(r"publish tick ([\d.]+) s late: ([^\n]*)", log_text)
    duration_s = samples[-1].at if samples else 0.0
    ended = soak.started + duration_s
    # Those the run's end cut short are left out; those STATUS was not sampled for are kept and count as untrue.
    seen = [s for s in outages_seen(soak, load, log_text)
            if s.outage.up is not None and s.outage.up + truth_s <= ended]
    silence_s, silence_at = longest_silence(load, soak.started, ended)
    first, last = samples[0], samples[-1]
    cpu = (last.cpu_s - first.cpu_s) / max(1e-9, last.at - first.at) * 100.0
    log_rate = (last.log_bytes - first.log_bytes) / max(1e-9, last.at - first.at) * 3600.0 / 1024.0
    untrue = [s for s in seen if s.noticed_s is None or s.noticed_s > truth_s or s.healed_s is None
              or s.healed_s > truth_s]
    wrong_length = [s for s in seen if s.logged_s is None or s.outage.up is None
                    or abs(s.logged_s - (s.outage.up - s.outage.down)) > truth_s]
    lines = [f"## {title}", "", what, "",
             f"Ran {duration_s / 60.0:.1f} min (asked: {minutes:g} min); stopped by SIGTERM in "
             f"{_fmt(soak.stop_s)} s, exit code {soak.exit_code}.", "",
             "| measurement | value |", "|---|---|",
             f"| RSS at start / peak / end | {first.rss_mib:.1f} / {max(s.rss_mib for s in samples):.1f} / "
             f"{last.rss_mib:.1f} MiB |",
             f"| RSS slope after {warmup_s / 60.0:g} min (least squares) | "
             f"{slope_mib_h(samples, warmup_s):+.2f} MiB/h |",
             f"| RSS slope over the whole run | {slope_mib_h(samples, 0.0):+.2f} MiB/h |",
             f"| threads (min-max) | {min(s.threads for s in samples)}-{max(s.threads for s in samples)} |",
             f"| open descriptors (min-max) | {min(s.fds for s in samples)}-{max(s.fds for s in samples)} |",
             f"| CPU | {cpu:.1f} % of one core |",
             f"| log growth | {log_rate:.1f} KiB/h ({last.log_bytes / 1024.0:.0f} KiB at the end) |",
             f"| longest feed gap per TCP WATCH client (gaps > {GAP_S} s) | {_gaps(load.feeds)} |",
             f"| longest gap per web stream, reconnections excluded (gaps > {GAP_S} s) | {_gaps(load.streams)} |",
             f"| a 50 ms sleeper in the benchmark's process: worst oversleep | {load.sleeper_late_s * 1e3:.0f} ms |",
             f"| stalls the station logged (tick >= 0.5 s late) | {len(stalls)}"
             + (f", longest {max(float(s[0]) for s in stalls):.2f} s" if stalls else "") + " |",
             f"| SAT= switches (refused or failed) | {load.switches} ({load.switch_failures}) |",
             f"| STATUS samples (failed); longest time without an answer | {len(load.links)} "
             f"({load.status_failures}); {silence_s:.1f} s from {silence_at / 60.0:.1f} min |",
             f"| outages injected (rotctld / rigctld) | {sum(o.daemon == 'rotctld' for o in soak.outages)} / "
             f"{sum(o.daemon == 'rigctld' for o in soak.outages)} |",
             f"| daemon restarts that failed and were retried | "
             f"{sum(len(o.restart_errors) for o in soak.outages)} |",
             f"| outages STATUS showed late (> {truth_s:g} s after the kill or the return) | {len(untrue)} |",
             f"| outages whose logged length is off by > {truth_s:g} s (or not logged) | {len(wrong_length)} |",
             ""]
    if stalls:
        lines += ["Stalls as the station explained them:", ""]
        lines += [f"- {late} s: {cause}" for late, cause in stalls[:10]]
        lines.append("")
    lines += ["| outage | down for | STATUS unreachable after | STATUS well after return | logged length |",
              "|---|---|---|---|---|"]
    for s in seen[:40]:
        length = (s.outage.up - s.outage.down) if s.outage.up is not None else None
        lines.append(f"| {s.outage.daemon} at {(s.outage.down - soak.started) / 60.0:.1f} min | {_fmt(length)} s | "
                     f"{_fmt(s.noticed_s)} s | {_fmt(s.healed_s)} s | {_fmt(s.logged_s)} s |")
    if len(seen) > 40:
        lines.append(f"| ... {len(seen) - 40} more | | | | |")
    lines += ["", "| minute | RSS MiB | threads | fds | CPU s | log KiB |", "|---|---|---|---|---|---|"]
    step = max(1, len(samples) // 12)
    for row in samples[::step] + ([samples[-1]] if (len(samples) - 1) % step else []):
        lines.append(f"| {row.at / 60.0:.1f} | {row.rss_mib:.1f} | {row.threads} | {row.fds} | {row.cpu_s:.0f} | "
                     f"{row.log_bytes / 1024.0:.0f} |")
    if plot is not None:
        lines += ["", f"![{title}]({plot.name})"]
    return "\n".join(lines) + "\n"


def plot(path: Path, title: str, soak: Soak, load: Load, warmup_s: float) -> Path | None:
    """RSS with its fit after warm-up, threads and descriptors, CPU and the longest feed gap: a PNG (None without
    matplotlib)."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return None
    samples = soak.samples
    minutes = [s.at / 60.0 for s in samples]
    fig, axes = plt.subplots(4, 1, figsize=(9, 10), sharex=True)
    axes[0].plot(minutes, [s.rss_mib for s in samples], label="RSS")
    late = [s for s in samples if s.at >= warmup_s]
    if len(late) >= 3:
        fit = np.polyfit([s.at for s in late], [s.rss_mib for s in late], 1)
        axes[0].plot([s.at / 60.0 for s in late], [fit[0] * s.at + fit[1] for s in late], "--",
                     label=f"fit after {warmup_s / 60.0:g} min: {fit[0] * 3600.0:+.2f} MiB/h")
    axes[0].set_ylabel("MiB")
    axes[0].legend(loc="lower right")
    axes[1].plot(minutes, [s.threads for s in samples], label="threads")
    axes[1].plot(minutes, [s.fds for s in samples], label="open descriptors")
    axes[1].legend(loc="lower right")
    cpu = [0.0] + [(b.cpu_s - a.cpu_s) / max(1e-9, b.at - a.at) * 100.0 for a, b in zip(samples, samples[1:])]
    axes[2].plot(minutes, cpu)
    axes[2].set_ylabel("CPU % of a core")
    for feed in load.feeds + load.streams:
        if feed.gaps:
            axes[3].scatter([(t - soak.started) / 60.0 for t, _ in feed.gaps], [g for _, g in feed.gaps], s=8,
                            label=feed.name)
    for outage in soak.outages:
        for ax in axes:
            ax.axvspan((outage.down - soak.started) / 60.0,
                       ((outage.up or outage.down) - soak.started) / 60.0,
                       color="red" if outage.daemon == "rotctld" else "orange", alpha=0.08)
    axes[3].set_ylabel(f"feed gaps > {GAP_S} s (s)")
    axes[3].set_xlabel("minutes (shaded: rotctld red, rigctld orange down)")
    if any(f.gaps for f in load.feeds + load.streams):
        axes[3].legend(loc="upper right", fontsize="small")
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return path
