"""Hamlib's daemons (rotctld, rigctld) over TCP: the line client and the command table.
"""
