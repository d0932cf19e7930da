"""Each command imports only what it uses: ``--version`` and ``status`` never load numpy, SGP4's engine or the
server, so they start as fast as the interpreter allows (measured in docs/BENCHMARKS.md, not here)."""

from __future__ import annotations

import json
import socket
import subprocess
import sys

from tests.conftest import ROOT

_SCRIPT = """
import json, sys
from nfwserver.cli import main
try:
    main(sys.argv[1:])
except SystemExit:
    pass
print(json.dumps(sorted(sys.modules)), file=sys.stderr)
"""


def _modules_after(*argv: str) -> set[str]:
    done = subprocess.run([sys.executable, "-c", _SCRIPT, *argv], cwd=ROOT, capture_output=True, text=True,
                          timeout=60)
    return set(json.loads(done.stderr.strip().splitlines()[-1]))


def _closed_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]  # closed again when the block ends


def test_version_loads_nothing_but_the_parser() -> None:
    loaded = {m for m in _modules_after("--version") if m.startswith(("nfwserver", "numpy", "sgp4"))}
    assert loaded == {"nfwserver", "nfwserver.blas_threads", "nfwserver.cli", "nfwserver.cli.arguments",
                      "nfwserver.cli.errors",  # CliError and say: the standard library only
                      "nfwserver.release"}  # the version, derived when asked (standard library only)


def test_status_loads_neither_numpy_nor_the_server() -> None:
    loaded = _modules_after("status", "--port", str(_closed_port()), "--timeout", "2")
    assert "nfwserver.tcp.client" in loaded and "nfwserver.config" in loaded  # it did ask
    for heavy in ("numpy", "nfwserver.core", "nfwserver.tcp.server", "nfwserver.tcp.protocol",
                  "nfwserver.tracking.derived", "nfwserver.tracking.elements"):
        assert heavy not in loaded, heavy
