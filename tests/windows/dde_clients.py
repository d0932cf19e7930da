"""A Windows program: N real DDEML clients holding hot advise loops on a running station.

``python dde_clients.py --clients 20 --seconds 60 --out FILE [--wait-disconnect 40]``

Each client runs on a thread of its own with its own DDEML instance (a DDEML rule), connects
(half to ``NFW32``, half to ``NFW_SERVER``; retrying while the station starts), pokes
``TUNE ON``, starts a hot advise loop on ``NFW_SERVER`` and counts the strings delivered during a
common window of ``--seconds``.  With ``--wait-disconnect`` it then keeps pumping until the station
ends the conversation (``XTYP_DISCONNECT``).  Results go to ``--out`` as JSON, one record per client.
"""

from __future__ import annotations

import argparse
import json
import sys
import threading
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent.parent))

from nfwserver.dde.ddeml_client import DdemlClient, DdeRefused  # noqa: E402

SERVICES = ("NFW32", "NFW_SERVER")


def run_client(index: int, args: argparse.Namespace, connected: threading.Barrier, out: dict) -> None:
    service = SERVICES[index % 2]
    record: dict = {"client": index, "service": service, "error": None}
    out[index] = record
    client = DdemlClient()
    try:
        deadline = time.monotonic() + args.connect_timeout
        while True:
            try:
                conv = client.connect(service, "NFW_DATA")
                break
            except DdeRefused:
                if time.monotonic() > deadline:
                    raise
                client.pump(0.25)
        client.poke(conv, "NFW_SERVER", "TUNE ON")
        client.start_advise(conv, "NFW_SERVER", hot=True)
    except Exception as exc:  # reported, and the barrier released for the others
        record["error"] = f"{type(exc).__name__}: {exc}"
        connected.abort()
        return
    try:
        connected.wait(args.connect_timeout + 30)
    except threading.BrokenBarrierError:
        record["error"] = "another client failed to connect"
        return
    start_count, start = client.advise_counts[conv], time.monotonic()
    client.pump(args.seconds)
    record["advise"] = client.advise_counts[conv] - start_count
    record["window_s"] = time.monotonic() - start
    record["still_connected"] = conv not in client.disconnected
    try:
        record["request_after"] = client.request_text(conv, "NFW_SERVER")
    except DdeRefused as exc:
        record["request_after"] = f"refused: {exc}"
    data = [d for _, d in client.received if d]
    record["sample"] = data[-1].split(b"\x00")[0].decode("cp1252") if data else ""
    client.received.clear()
    if args.wait_disconnect:
        t0 = time.monotonic()
        record["disconnected"] = client.pump(args.wait_disconnect, until=lambda: conv in client.disconnected)
        record["disconnect_wait_s"] = time.monotonic() - t0
    client.close()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--clients", type=int, default=20)
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--connect-timeout", type=float, default=60.0)
    parser.add_argument("--wait-disconnect", type=float, default=0.0)
    parser.add_argument("--out", required=True)
    args = parser.parse_args(argv)
    connected = threading.Barrier(args.clients)
    results: dict[int, dict] = {}
    threads = [threading.Thread(target=run_client, args=(i, args, connected, results), daemon=True)
               for i in range(args.clients)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(args.connect_timeout + args.seconds + args.wait_disconnect + 60)
    Path(args.out).write_text(json.dumps([results.get(i, {"client": i, "error": "no result"})
                                          for i in range(args.clients)], indent=1))
    return 0 if all(r.get("error") is None for r in results.values()) and len(results) == args.clients else 1


if __name__ == "__main__":
    sys.exit(main())
