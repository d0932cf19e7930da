"""A Windows program standing in for a Windows-only rotor controller: it reads Nova's DDE feed and
points a rotator through Hamlib's ``rotctld`` network protocol (see docs/WINE.md).

``python dde_rotor_client.py --rotctld HOST:PORT --seconds 5 --out FILE``

It connects to ``NFW32``/``NFW_DATA`` the way rotor programs do (poke ``TUNE ON``, hot advise loop
on ``NFW_SERVER``), parses ``AZ:`` and ``EL:`` from each string, and sends ``P az el`` to rotctld for
each new position.  The last string and the last position sent go to ``--out`` as JSON.
"""

from __future__ import annotations

import argparse
import json
import re
import socket
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent.parent))

from nfwserver.dde.ddeml_client import DdemlClient, DdeRefused  # noqa: E402

AZ_EL = re.compile(r" AZ:(\d+\.\d) EL:(-?\d+\.\d) ")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rotctld", required=True, help="HOST:PORT")
    parser.add_argument("--seconds", type=float, default=5.0)
    parser.add_argument("--out", required=True)
    args = parser.parse_args(argv)
    host, port = args.rotctld.rsplit(":", 1)
    client = DdemlClient(ansi=True)
    for attempt in range(240):  # the station may still be starting: retry for up to a minute
        try:
            conv = client.connect("NFW32", "NFW_DATA")
            break
        except DdeRefused:
            if attempt == 239:
                raise
            client.pump(0.25)
    client.poke(conv, "NFW_SERVER", "TUNE ON")
    client.start_advise(conv, "NFW_SERVER", hot=True)
    sent: list[tuple[float, float]] = []
    last = ""
    with socket.create_connection((host, int(port)), timeout=5) as rot:
        reader = rot.makefile("rb")
        for _ in range(int(args.seconds * 4)):
            client.pump(0.25)
            texts = [d.split(b"\x00")[0].decode("cp1252") for _, d in client.received if d]
            client.received.clear()
            match = AZ_EL.search(texts[-1]) if texts else None
            if match:
                last = texts[-1]
                az, el = float(match.group(1)), float(match.group(2))
                if not sent or sent[-1] != (az, el):
                    rot.sendall(f"P {az:.1f} {el:.1f}\n".encode())
                    reply = reader.readline().decode().strip()
                    if reply != "RPRT 0":
                        raise SystemExit(f"rotctld refused P {az} {el}: {reply}")
                    sent.append((az, el))
    client.disconnect(conv)
    client.close()
    Path(args.out).write_text(json.dumps({"last": last, "sent": sent}))
    return 0 if sent else 1


if __name__ == "__main__":
    sys.exit(main())
