#!/usr/bin/python3
"""A Modbus-ASCII slave made from pymodbus (Debian python3-pymodbus 3.0) for the Serial
Gateway tests: modbus_ascii_slave.py DEVICE SLAVE_ID. pymodbus's ASCII framer decodes each
request, its request objects execute against its data store, and the framer builds the
answer (':' ... LRC CR LF). Holding register n starts as n. Prints "ready"; ends when the
line goes away. (pymodbus's own serial server needs serial_asyncio, not in Debian's
package set here, so this loop reads the line with pyserial.)"""
import sys

import serial
from pymodbus.datastore import ModbusSequentialDataBlock, ModbusSlaveContext
from pymodbus.factory import ServerDecoder
from pymodbus.transaction import ModbusAsciiFramer


def main():
    device, slave_id = sys.argv[1], int(sys.argv[2])
    block = ModbusSequentialDataBlock(0, list(range(100)))
    store = ModbusSlaveContext(hr=block, ir=block, co=block, di=block, zero_mode=True)
    framer = ModbusAsciiFramer(ServerDecoder())
    line = serial.Serial(device, 9600, timeout=None)
    print("ready", flush=True)

    def answer(request):
        if request.unit_id != slave_id:
            return
        response = request.execute(store)
        response.transaction_id = request.transaction_id
        response.unit_id = request.unit_id
        line.write(framer.buildPacket(response))

    while True:
        try:
            data = line.read(1)
            if line.in_waiting:
                data += line.read(line.in_waiting)
        except (serial.SerialException, OSError):
            return
        if not data:
            return
        framer.processIncomingPacket(data, answer, unit=[slave_id], single=False)


if __name__ == "__main__":
    main()
