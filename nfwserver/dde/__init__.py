"""Nova for Windows' DDE interface: the Nova adapter, the transport interface, the Windows DDEML transport.
"""
