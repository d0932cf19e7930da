"""WXtrack's DDE interface: service ``WXtrack``, topic and item ``Tracking``; Orbitron's TrackingData format."""

from __future__ import annotations

from nfwserver.dialects.base import Dialect
from nfwserver.dialects.orbitron import format_tracking_data

WXTRACK = Dialect("wxtrack", "WXtrack", "Tracking", ("Tracking",), format_tracking_data)
