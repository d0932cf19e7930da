"""The Nova for Windows DDE interface: protocol, transport-agnostic server core, Windows transport."""
