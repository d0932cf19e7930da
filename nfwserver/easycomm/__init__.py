"""EasyComm I serial output for Arduino, K3NG-style and other EasyComm rotor controllers."""

from nfwserver.easycomm.output import EasyCommOutput

__all__ = ["EasyCommOutput"]
