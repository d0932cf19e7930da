"""Hamlib's RPRT error codes and their meaning."""

from __future__ import annotations

RPRT_MEANING = {
    0: "ok",
    -1: "invalid parameter",
    -2: "invalid configuration",
    -3: "out of memory",
    -4: "function not implemented",
    -5: "communication timed out",
    -6: "I/O error",
    -7: "internal Hamlib error",
    -8: "protocol error",
    -9: "command rejected by the device",
    -10: "command arguments truncated",
    -11: "function not available",
    -12: "VFO not targetable",
    -13: "bus error",
    -14: "bus busy",
    -15: "invalid argument",
    -16: "invalid VFO",
    -17: "argument out of domain",
}


def describe_rprt(code: int) -> str:
    return RPRT_MEANING.get(code, f"unknown error {code}")
