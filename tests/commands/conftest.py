"""The TCP station fixtures, shared with tests/tcp."""

from tests.tcp.conftest import client, tcp_station  # noqa: F401
