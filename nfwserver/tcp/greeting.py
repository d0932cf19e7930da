"""The line Nova's TCP server sends first to every client (its own module, so a client need not load the server)."""

GREETING = "Hello, this is Nova for Windows."
