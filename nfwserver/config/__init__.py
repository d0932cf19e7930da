"""Configuration: one table of sections and keys, from which validation, ``config show`` and the
``config init`` template are generated; the TOML file's location; reading user files safely.

The package imports nothing (each name is imported from its module): reading a file through
:mod:`nfwserver.config.files`, or a default from :mod:`nfwserver.config.table`, does not build the
configuration's record types (:mod:`nfwserver.config.schema`), which cost a command as much at start as a
day of one satellite's passes.
"""
