"""Satellite radio channels: the plain record the station state holds (:mod:`~nfwserver.channels.channel`) and
the operating mode names it accepts (:mod:`~nfwserver.channels.modes`).

A neutral package: the core, the configuration and every adapter (radio, dialects, EasyComm) import it, and it
imports none of them, so the core does not depend on the radio adapter and light commands (``nfwserver
status``) can read a configuration without loading the core.
"""
