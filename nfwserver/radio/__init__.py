"""Doppler tuning through Hamlib's rigctld (the channels it tunes are the core's:
:class:`nfwserver.channels.channel.Channel`).
"""
