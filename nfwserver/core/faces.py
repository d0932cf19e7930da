"""What readers (the console, the web page, the headless status line) use of an output face, as protocols.

A face built only when configured (TCP, EasyComm) or living in another package (the Nova DDE service) is
typed by what its readers call on it, not by its class: the readers stay free of the face's imports,
and a stand-in with the same members will do.
"""

from __future__ import annotations

from typing import Protocol


class CountsClients(Protocol):
    """A listener that counts its connected clients (:class:`nfwserver.tcp.server.NovaTcpServer`)."""

    def client_count(self) -> int: ...


class CountsConversations(Protocol):
    """A DDE service that counts (open conversations, advise loops)
    (:class:`nfwserver.dde.nova_service.NovaDdeService`)."""

    def client_count(self) -> tuple[int, int]: ...


class WritesLines(Protocol):
    """An output that keeps the last line it wrote (:class:`nfwserver.easycomm.output.EasyCommOutput`)."""

    @property
    def last_line(self) -> str: ...
