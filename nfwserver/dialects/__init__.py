"""Other trackers' interfaces served from the same session: Orbitron, WXtrack and SatPC32 DDE, PREDICT's UDP.

Each DDE dialect is a small :class:`~nfwserver.dialects.base.Dialect` record (names and a formatter);
:class:`~nfwserver.dialects.dde_service.DialectServer` serves any of them on a DDE transport next to
Nova's, updated from the Nova core's ticks.  :mod:`nfwserver.dialects.predict_udp` serves PREDICT's UDP
socket protocol (:mod:`~nfwserver.dialects.predict_protocol`; listings in
:mod:`~nfwserver.dialects.predict_listing`).
"""
