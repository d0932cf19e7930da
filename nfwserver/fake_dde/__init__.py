"""An in-process DDEML: the production DDE transport on Linux (and anywhere without Windows DDE),
the stand-in for Windows DDEML in tests, and a way to check your own client logic.

It lives in its own package (the layout the project's owner asked for), but it is not test-only code:
``nfwserver run`` serves on it whenever real DDEML is unavailable, and the console and
``nfwserver simulate`` are its clients.

It keeps DDEML's rules so code that works here works against Windows DDE:

- A :class:`FakeDdeSystem` stands for one Windows session.  Servers register service names on it
  through :meth:`FakeDdeSystem.server_transport` (the :class:`~nfwserver.dde.transport.DdeServerTransport`
  the nfwserver core uses); clients open conversations with :meth:`FakeDdeSystem.connect`.
- Service, topic and item names compare case-insensitively and are limited to 255 characters.
- Per conversation a client can request, poke and execute, start an advise loop on (item, format)
  -- hot (the data is pushed) or warm (only a notification; the client then requests) -- stop it,
  and disconnect.  A second advise start on the same loop changes its link type instead of
  creating another loop.  An advise start the server refuses (unknown item) fails.
- Data crosses as bytes in a clipboard format (``CF_TEXT``: ANSI with a trailing NUL;
  ``CF_UNICODETEXT``: UTF-16-LE with a two-byte NUL).
- Failures come back as :class:`DdeError` carrying DDEML's ``DMLERR_*`` code, as
  ``DdeGetLastError`` would report after a failed ``DdeClientTransaction``.
- A server callback that raises refuses that one transaction; every other conversation goes on.
- Each client conversation records, in order, everything it received (:attr:`ClientConversation.received`).

Example::

    system = FakeDdeSystem()
    core = StationCore(catalog, observer, clock, satellite=25544)
    NovaDdeService(core).attach(system.server_transport())
    conv = system.connect("NFW32", "NFW_DATA")
    conv.poke("NFW_SERVER", "TUNE ON")
    conv.start_advise("NFW_SERVER")          # hot link
    ...
    print(conv.texts())
"""

from nfwserver.fake_dde.errors import (
    DMLERR_BUSY,
    DMLERR_INVALIDPARAMETER,
    DMLERR_NO_CONV_ESTABLISHED,
    DMLERR_NOTPROCESSED,
    DMLERR_SERVER_DIED,
    DdeError,
)
from nfwserver.fake_dde.system import ClientConversation, FakeDdeSystem, FakeServerTransport, Received

__all__ = [
    "DMLERR_BUSY",
    "DMLERR_INVALIDPARAMETER",
    "DMLERR_NOTPROCESSED",
    "DMLERR_NO_CONV_ESTABLISHED",
    "DMLERR_SERVER_DIED",
    "ClientConversation",
    "DdeError",
    "FakeDdeSystem",
    "FakeServerTransport",
    "Received",
]
