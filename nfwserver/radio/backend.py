"""What the tuning logic needs from a radio, and the errors a backend reports."""

from __future__ import annotations

from typing import Protocol


class RadioError(Exception):
    """The radio refused or failed a command; the message says which and why."""


class RadioUnavailable(RadioError):
    """The radio (or its daemon) cannot be reached right now; the backend retries later by itself."""


class RadioBackend(Protocol):
    """A transceiver: frequencies are integer Hz."""

    def set_rx_frequency(self, hz: int) -> None: ...

    def get_rx_frequency(self) -> int: ...

    def set_tx_frequency(self, hz: int) -> None: ...

    def get_tx_frequency(self) -> int: ...

    def set_split(self, on: bool) -> None: ...

    def set_modes(self, rx_mode: str, tx_mode: str | None) -> None: ...

    def close(self) -> None: ...
