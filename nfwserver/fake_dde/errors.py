"""DDEML error codes (the values ``DdeGetLastError`` returns) and the exception that carries them."""

from __future__ import annotations

DMLERR_ADVACKTIMEOUT = 0x4000
DMLERR_BUSY = 0x4001
DMLERR_DATAACKTIMEOUT = 0x4002
DMLERR_DLL_NOT_INITIALIZED = 0x4003
DMLERR_DLL_USAGE = 0x4004
DMLERR_EXECACKTIMEOUT = 0x4005
DMLERR_INVALIDPARAMETER = 0x4006
DMLERR_LOW_MEMORY = 0x4007
DMLERR_MEMORY_ERROR = 0x4008
DMLERR_NOTPROCESSED = 0x4009
DMLERR_NO_CONV_ESTABLISHED = 0x400A
DMLERR_POKEACKTIMEOUT = 0x400B
DMLERR_POSTMSG_FAILED = 0x400C
DMLERR_REENTRANCY = 0x400D
DMLERR_SERVER_DIED = 0x400E
DMLERR_SYS_ERROR = 0x400F
DMLERR_UNADVACKTIMEOUT = 0x4010
DMLERR_UNFOUND_QUEUE_ID = 0x4011

_NAMES = {v: k for k, v in globals().items() if k.startswith("DMLERR_")}


class DdeError(Exception):
    """A DDE transaction failed; ``code`` is the DMLERR_* value."""

    def __init__(self, code: int, message: str) -> None:
        self.code = code
        super().__init__(f"{_NAMES.get(code, hex(code))}: {message}")
