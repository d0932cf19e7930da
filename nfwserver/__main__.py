"""Allow ``python -m nfwserver``."""

from nfwserver.cli import main

raise SystemExit(main())
