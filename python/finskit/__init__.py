"""Omron FINS for Python: libfins's client and finsd's virtual PLC.

    import finskit
    with finskit.VirtualPlc(profile="cj2h") as plc:
        with finskit.Client(plc.host, plc.port) as client:
            client.write_words("D100", [1, 2, 3])
            assert client.read_words("D100", 3) == [1, 2, 3]

A non-zero end code raises finskit.FinsError (.code, .name, .meaning); a timeout raises
TimeoutError, a bad address ValueError, a lost connection ConnectionError.
"""
from ._finskit import Client, CpuStatus, FinsError, VirtualPlc

__all__ = ["Client", "CpuStatus", "FinsError", "VirtualPlc"]
__version__ = "0.1.0"
