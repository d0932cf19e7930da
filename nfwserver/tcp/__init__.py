"""Nova's TCP server: a greeting, ``SUMMARY``, the Nova commands, ``STATUS`` and ``WATCH`` on port 8090."""

from nfwserver.tcp.protocol import GREETING, NovaTcpProtocol
from nfwserver.tcp.server import NovaTcpServer

__all__ = ["GREETING", "NovaTcpProtocol", "NovaTcpServer"]
