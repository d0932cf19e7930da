"""Operating modes as Hamlib names them (``rigctld``'s ``M``/``X`` commands and ``m`` replies).

The set is Hamlib 4.5's mode table (``rig_strrmode``/``rig_parse_mode``), aliases included
(``USB-D`` is ``PKTUSB``, ``CW-R`` is ``CWR``).  ``rigctld`` answers ``RPRT 0`` to a name outside
it and leaves the mode unchanged, so a misspelt mode would pass unnoticed: channels refuse such
names when they are built (:class:`nfwserver.channels.channel.Channel`).
"""

from __future__ import annotations

HAMLIB_MODES: frozenset[str] = frozenset({
    "AM", "AMN", "AMS", "AM-D", "PKTAM", "SAM", "SAL", "SAH", "DSB",
    "CW", "CWN", "CWR", "CW-R",
    "USB", "LSB", "PKTUSB", "PKTLSB", "USB-D", "LSB-D", "ECSSUSB", "ECSSLSB", "ISBUSB", "ISBLSB",
    "RTTY", "RTTYR", "RTTY-R", "PSK", "PSKR", "FAX",
    "FM", "FMN", "WFM", "PKTFM", "PKTFMN", "FM-D",
    "P25", "D-STAR", "DPMR", "NXDN-VN", "NXDN-N", "DCR", "C4FM", "SPEC", "IQ",
})


def check_mode(mode: object, what: str = "mode") -> str:
    """``mode`` in upper case if Hamlib knows it; else :class:`ValueError` naming the valid ones."""
    if not isinstance(mode, str) or mode.strip().upper() not in HAMLIB_MODES:
        raise ValueError(f"{what} {mode!r} is not a Hamlib mode (one of {', '.join(sorted(HAMLIB_MODES))})")
    return mode.strip().upper()
