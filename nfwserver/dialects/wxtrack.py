"""WXtrack's DDE interface: service ``WXtrack``, topic ``Tracking``, item ``Tracking``, Orbitron's string format."""

from __future__ import annotations

from nfwserver.dialects.base import Dialect
from nfwserver.dialects.orbitron import format_orbitron

WXTRACK = Dialect("wxtrack", "WXtrack", "Tracking", ("Tracking",), format_orbitron)
