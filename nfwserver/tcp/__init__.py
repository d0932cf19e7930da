"""Nova's TCP server: a greeting, ``SUMMARY``, the Nova commands, ``STATUS`` and ``WATCH`` on port 8090.

The package imports nothing (each name is imported from its module), so that the one-question client
(``nfwserver status``, ``poke``) does not load the server and the station core.
"""
