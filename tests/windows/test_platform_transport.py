"""The default transport: real DDEML on Windows, and a station that still runs when DDEML cannot start."""

from __future__ import annotations

import sys

import pytest

from nfwserver.app.platform_transport import FAKE_NOTE, default_transport
from nfwserver.fake_dde import FakeDdeSystem


def _is_fake(transport) -> bool:
    return type(transport) is type(FakeDdeSystem().server_transport())


@pytest.mark.skipif(sys.platform == "win32", reason="checks the fallback where DDEML cannot exist")
def test_windows_transport_failing_with_oserror_falls_back_to_the_fake_transport(caplog) -> None:
    # Off Windows the real WindowsDdeTransport raises OSError at construction, exactly the failure
    # the old fallback (catching only ImportError) let through.
    transport, note = default_transport("win32")
    assert _is_fake(transport)
    assert note.startswith("real DDE failed to start (") and "fake DDE transport" in note
    assert any("Windows DDE transport did not start" in r.message for r in caplog.records)


def test_other_platforms_get_the_fake_transport() -> None:
    transport, note = default_transport("linux")
    assert _is_fake(transport) and note == FAKE_NOTE
