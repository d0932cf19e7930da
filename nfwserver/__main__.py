"""Allow ``python -m nfwserver``."""

from nfwserver.cli import entry

raise SystemExit(entry())
