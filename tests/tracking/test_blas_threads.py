"""The tracking engine keeps a process single-threaded: no idle BLAS worker threads (Linux /proc)."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from tests.conftest import ROOT

_SCRIPT = """
import os
{first}
import nfwserver.tracking.passes, numpy
numpy.ones((4000, 3)) @ numpy.ones(3)  # large enough for OpenBLAS to use its threads, if it has any
print(os.environ.get("OPENBLAS_NUM_THREADS"), len(os.listdir("/proc/self/task")))
"""


def _run(first: str = "", **env: str) -> list[str]:
    clean = {k: v for k, v in os.environ.items() if not k.endswith("_NUM_THREADS")}
    done = subprocess.run([sys.executable, "-c", _SCRIPT.format(first=first)], cwd=ROOT, capture_output=True,
                          text=True, env={**clean, **env}, timeout=60, check=True)
    return done.stdout.split()


@pytest.mark.skipif(not os.path.isdir("/proc/self/task"), reason="needs Linux /proc")
def test_importing_the_engine_leaves_one_thread_unless_the_user_chose() -> None:
    assert _run() == ["1", "1"]
    assert _run(OPENBLAS_NUM_THREADS="2")[0] == "2"  # the user's choice stands
    assert _run("import numpy")[0] == "None"  # too late to choose once numpy is loaded: left alone
