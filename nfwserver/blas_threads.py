"""One BLAS thread for the process, unless the user chose: set before numpy loads.

The engine's arrays are small (thousands of 3-vectors): BLAS threads gain nothing on them, yet OpenBLAS
starts one per core when numpy loads (~0.1 s of CPU, 40 ms of wall time on a 2-core machine) and they
spin after every large matrix product.  Called by the tracking package and by the command line before
anything imports numpy; once numpy is loaded it is too late, and nothing is changed.
"""

from __future__ import annotations

import os
import sys


def single_threaded_blas() -> None:
    """Ask OpenBLAS for one thread (``OPENBLAS_NUM_THREADS=1``) unless numpy is loaded or the user set it."""
    if "numpy" not in sys.modules:
        os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
