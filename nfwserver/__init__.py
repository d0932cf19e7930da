"""nfwserver: a satellite-tracking server that stands in for Nova for Windows on its DDE interface.

Sub-packages:

- :mod:`nfwserver.tracking` -- element files, SGP4 look angles, passes, Doppler (numpy).
- :mod:`nfwserver.dde` -- the Nova protocol, the transport-agnostic server core, the Windows DDEML transport.
- :mod:`nfwserver.fake_dde` -- an in-process DDEML with the same semantics, for Linux and for tests.
- :mod:`nfwserver.rotor` -- the Kansas City Tracker driver model, flip tracking, rotor backends.
- :mod:`nfwserver.radio` -- Doppler tuning and radio backends.
- :mod:`nfwserver.console` -- the diagnostic console.
- :mod:`nfwserver.cli` -- the ``nfwserver`` command.

``nfwserver.__version__`` is derived from the repository when first asked for (:mod:`nfwserver.release`).
"""


def __getattr__(name: str) -> str:
    if name == "__version__":
        from nfwserver.release import package_version

        return package_version()
    raise AttributeError(f"module 'nfwserver' has no attribute {name!r}")
