"""The hostile-input families: element files, configurations, DDE pokes, TCP lines, PREDICT datagrams.

Each ``run_*`` takes a :class:`~bench.campaign.tally.Tally` (called inside
:func:`~bench.campaign.tally.run_family`, which counts logged tracebacks and dead threads) and a count.
Expected answers come from the protocols' own rules written out here (an independent line splitter for
TCP, one datagram per PREDICT request, UPDATE's newest-epoch-wins for the store), not from our code.
"""

from __future__ import annotations

import contextlib
import io
import re
import socket
import threading
import time
from collections import Counter
from pathlib import Path

from bench.campaign.fuzz_elements import SOURCE_SETS, ElementFuzzer
from bench.campaign.fuzz_lines import ConfigFuzzer, DatagramFuzzer, PokeFuzzer, make_fifo
from bench.campaign.station_rig import GREETING, StationRig
from bench.campaign.tally import Tally
from nfwserver.app.element_store import ElementStore
from nfwserver.app.station import Station
from nfwserver.clock import SystemClock
from nfwserver.config.loader import ConfigError, parse_config
from nfwserver.fake_dde import DdeError, FakeDdeSystem
from nfwserver.tracking.elements import load_element_file, load_elements


def _read_back_whole(es) -> bool:
    """An accepted set, stored as text and read again, is the same set with a printable name (a set
    without a name is stored under its catalog number)."""
    again = load_elements(es.tle_text(), "stored").sets
    return (len(again) == 1 and again[0].line1 == es.line1 and again[0].line2 == es.line2
            and again[0].name == (es.name or str(es.catalog_number)) and es.name.isprintable())


def run_element_files(tally: Tally, count: int, seed: int) -> None:
    fuzzer = ElementFuzzer(seed)
    kinds: Counter[str] = Counter()
    accepted = rejected = 0
    for _ in range(count):
        kind, data = fuzzer.next_file()
        kinds[kind] += 1
        tally.tried += 1
        try:
            result = load_elements(data, f"fuzz-{kind}")
        except Exception as exc:
            tally.crash(f"load_elements on a {kind} file", exc)
            continue
        accepted += len(result.sets)
        rejected += len(result.rejected)
        if any(not r.reason for r in result.rejected):
            tally.loss(f"a rejection without a reason ({kind})")
        for es in result.sets:
            if not _read_back_whole(es):
                tally.loss(f"accepted set {es.catalog_number} ({kind}) does not read back whole")
    tally.extra.update({"sets accepted": accepted, "sets rejected with a reason": rejected,
                        "files by format": dict(sorted(kinds.items()))})


def _newest(sets, into: dict) -> None:
    for es in sets:
        if es.catalog_number not in into or es.epoch > into[es.catalog_number]:
            into[es.catalog_number] = es.epoch


def run_element_updates(tally: Tally, count: int, seed: int, workdir: Path) -> None:
    """Fuzzed files through ``nfwserver elements update`` (the CLI, in process); the store must stay whole
    and hold, for every satellite, the newest epoch it was ever given."""
    from nfwserver.cli import main

    fuzzer = ElementFuzzer(seed + 1)
    store = workdir / "update-store.txt"
    ElementStore(store).update(load_element_file(SOURCE_SETS).sets)
    expected: dict[int, object] = {}
    _newest(load_element_file(store).sets, expected)
    codes: Counter[int] = Counter()
    for k in range(count):
        kind, data = fuzzer.next_file()
        path = workdir / f"fuzz-{k % 4}.{ 'json' if kind == 'omm-json' else 'txt'}"
        path.write_bytes(data if isinstance(data, bytes) else data.encode("utf-8", errors="surrogatepass"))
        tally.tried += 1
        err = io.StringIO()
        try:
            with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
                code = main(["elements", "update", str(path), "--store", str(store)])
        except BaseException as exc:  # SystemExit included: argparse must not refuse a readable file
            tally.crash(f"elements update on a {kind} file", exc)
            continue
        codes[code] += 1
        if "Traceback" in err.getvalue():
            tally.tracebacks += 1
            tally.note(f"traceback on stderr of elements update ({kind})")
        if code not in (0, 1):
            tally.crash(f"elements update exit status {code}")
        if code == 0:
            _newest(load_elements(data, "again").sets, expected)
        stored = load_element_file(store)
        if stored.rejected:
            tally.loss(f"the store has {len(stored.rejected)} unreadable sets after a {kind} update")
        have: dict[int, object] = {}
        _newest(stored.sets, have)
        wrong = [n for n, epoch in expected.items() if have.get(n) != epoch]
        if wrong:
            tally.loss(f"{len(wrong)} satellites not at their newest epoch after a {kind} update", len(wrong))
            expected.update({n: have[n] for n in wrong if n in have})  # count each loss once
        if list(workdir.glob(".update-store.txt.*.tmp")):
            tally.loss("a temporary was left beside the store")
    tally.extra.update({"exit statuses": dict(sorted(codes.items())), "satellites in the store": len(expected)})


def _parse_bounded(text: str, workdir: Path, timeout_s: float = 5.0):
    """parse_config on its own thread: returns (config | ConfigError | exception, finished in time)."""
    box: list[object] = []

    def parse() -> None:
        try:
            box.append(parse_config(text, str(workdir / "fuzz.toml"), base_dir=workdir))
        except Exception as exc:  # ConfigError included; sorted out by the caller
            box.append(exc)

    thread = threading.Thread(target=parse, name="campaign-parse", daemon=True)
    thread.start()
    thread.join(timeout_s)
    return (box[0] if box else None), not thread.is_alive()


def run_configs(tally: Tally, count: int, seed: int, workdir: Path) -> None:
    fuzzer = ConfigFuzzer(seed, make_fifo(workdir))
    accepted = refused = 0
    for _ in range(count):
        text = fuzzer.next_text()
        tally.tried += 1
        outcome, finished = _parse_bounded(text, workdir)
        if not finished:
            tally.crash(f"parse_config blocked for 5 s on {text[:120]!r}")
            continue
        if isinstance(outcome, ConfigError):
            refused += 1
            if not outcome.problems or not all(isinstance(p, str) and p for p in outcome.problems):
                tally.loss("a refusal without a reason")
            continue
        if isinstance(outcome, Exception):
            tally.crash(f"parse_config on {text[:120]!r}", outcome)
            continue
        accepted += 1
        try:  # an accepted configuration must also build a station (construction does no I/O)
            Station(outcome, SystemClock(), transport=FakeDdeSystem().server_transport())
        except Exception as exc:
            tally.crash(f"Station() on an accepted configuration {text[:120]!r}", exc)
    tally.extra.update({"accepted": accepted, "refused with reasons": refused})


def run_dde_pokes(tally: Tally, rig: StationRig, count: int, seed: int) -> None:
    fuzzer = PokeFuzzer(seed)
    conv = rig.system.connect("NFW32", "NFW_DATA", "campaign-fuzz")
    refused = 0
    for k in range(count):
        poke = fuzzer.next_poke()
        tally.tried += 1
        try:
            if k % 10 == 7:
                conv.execute(poke)
            elif k % 20 == 3:
                conv.poke("NFW_DATA" if k % 40 == 3 else "NOT_AN_ITEM", poke)
            else:
                conv.poke("NFW_SERVER", poke)
        except DdeError:
            refused += 1
        except Exception as exc:
            tally.crash(f"poke {poke[:80]!r}", exc)
        if not conv.connected:
            tally.note("the fuzzing conversation was ended by the server")
            conv = rig.system.connect("NFW32", "NFW_DATA", "campaign-fuzz")
        if k % 1000 == 999:
            rig.check(tally, settle_s=0.2)
    conv.disconnect()
    rig.check(tally)
    tally.extra["refused"] = refused


_TERMINATOR = re.compile(rb"\r\n|[\r\n\x00]")


def expected_replies(data: bytes, limit: int = 1024) -> int:
    """Replies Nova's TCP server owes for ``data`` (ending in a terminator): one per line that is not blank,
    one per line over ``limit`` bytes; lines end at CR LF, CR, LF or NUL, and a blank line holds only ASCII
    white space (blanks, tabs, VT, FF, the 0x1C-0x1F separators) (docs of the TCP server)."""
    lines = _TERMINATOR.split(data)[:-1]
    return sum(1 for line in lines if len(line) > limit or line.decode("ascii", "replace").strip(_ASCII_SPACE))


#: The white space of a blank line: ASCII's (Python's ``str.strip`` on ASCII text strips exactly these).
_ASCII_SPACE = " \t\x0b\x0c\x1c\x1d\x1e\x1f"


def _is_mode_change(data: bytes) -> bool:
    return any(line.decode("ascii", "replace").strip(" \t").upper() in ("WATCH", "QUIT")
               for line in _TERMINATOR.split(data))


def run_tcp_lines(tally: Tally, rig: StationRig, count: int, seed: int) -> None:
    fuzzer = PokeFuzzer(seed + 7)
    sock = socket.create_connection(rig.station.tcp.address, timeout=5.0)
    buffer = b""
    while GREETING not in buffer:
        buffer += sock.recv(4096)
    buffer = buffer.split(GREETING, 1)[1]
    owed = answered = 0
    for k in range(count):
        line = fuzzer.next_line()
        data = line + b"\r\n"
        if _is_mode_change(data):  # WATCH and QUIT are the watcher's business; keep this a request stream
            data = b"SUMMARY\r\n"
        tally.tried += 1
        want = expected_replies(data)
        owed += want
        sock.sendall(data)
        deadline = time.monotonic() + 5.0
        while buffer.count(b"\r\n") < want and time.monotonic() < deadline:
            sock.settimeout(max(0.01, deadline - time.monotonic()))
            try:
                chunk = sock.recv(65536)
            except TimeoutError:
                break
            if not chunk:
                tally.loss("the server closed the request connection")
                return
            buffer += chunk
        got = min(want, buffer.count(b"\r\n"))
        answered += got
        if got < want:
            tally.loss(f"{want - got} replies missing for {data[:60]!r}", want - got)
        for _ in range(got):
            buffer = buffer.split(b"\r\n", 1)[1]
        if k % 1000 == 999:
            rig.check(tally, settle_s=0.2)
    time.sleep(0.3)
    sock.settimeout(0.2)
    with contextlib.suppress(TimeoutError):
        buffer += sock.recv(65536)
    tally.extra.update({"replies owed / received": f"{owed} / {answered}",
                        "unexpected extra lines": buffer.count(b"\r\n")})
    sock.close()
    rig.check(tally)


def run_predict_datagrams(tally: Tally, rig: StationRig, count: int, seed: int) -> None:
    from nfwserver.dialects.predict_protocol import END_OF_LISTING

    fuzzer = DatagramFuzzer(seed)
    server = rig.station.predict
    client = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    client.settimeout(3.0)
    huh = listing_lines = 0
    for k in range(count):
        data = fuzzer.next_datagram()
        tally.tried += 1
        listing = server.protocol.is_listing(data)
        client.setblocking(False)
        with contextlib.suppress(BlockingIOError):
            while True:
                client.recv(65536)  # leftovers of a listing that ran past its wait
        client.settimeout(3.0 if not listing else 20.0)
        client.sendto(data, server.address)
        try:
            reply = client.recv(65536)
            while listing and not reply.endswith(END_OF_LISTING):
                listing_lines += 1
                reply = client.recv(65536)
        except TimeoutError:
            tally.loss(f"no {'end of listing' if listing else 'reply'} for {data[:60]!r}")
            continue
        huh += reply == b"Huh?\n"
        if k % 1000 == 999:
            rig.check(tally, settle_s=0.2)
    client.close()
    rig.check(tally)
    tally.extra.update({"answered Huh?": huh, "listing lines": listing_lines})
