"""Package faces that import on first use: ``__all__`` without loading every module at import time.

Each package's ``__init__`` lists its public names and the module that defines each; the module is
imported only when the name is first looked up (PEP 562), so ``import nfwserver.dde.clipboard`` does
not pull in numpy and SGP4, and every command of the CLI starts quickly.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable


def lazy_exports(package: str, exports: dict[str, str]) -> Callable[[str], object]:
    """A module ``__getattr__`` serving ``exports`` (public name -> module name within ``package``)."""

    def __getattr__(name: str) -> object:
        module = exports.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        return getattr(importlib.import_module(f"{package}.{module}"), name)

    return __getattr__
