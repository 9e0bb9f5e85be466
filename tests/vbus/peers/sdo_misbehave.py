#!/usr/bin/env python3
"""An SDO server that breaks the protocol on purpose, written with python-can alone.

    python3 sdo_misbehave.py IFACE NODE

What it does is chosen by the index the client reads (any sub-index):

  0x2000  segmented upload announcing 10 bytes, then 7-byte segments that never end
  0x2001  a truncated expedited answer: 4 bytes (4B 01 20 00) instead of 8
  0x2002  block upload without a size whose sub-blocks never end
  0x2004  an upload answered with a download response (wrong command specifier)
  other   abort 0x06020000 (object does not exist)

Prints "sdo_misbehave ready IFACE NODE" once listening and, for every abort the client
sends, "sdo_misbehave abort CODE IIII:SS after SECONDS" (hex; SECONDS between the kernel
receive timestamps of the transfer's first request and of the abort). Stops on SIGTERM or
SIGINT.
"""

import signal
import struct
import sys

import can


class Misbehave:
    """The server's state for one client: the mode of the transfer running, if any."""

    def __init__(self, bus, node):
        self.bus = bus
        self.node = node
        self.mode = None
        self.toggle = 0
        self.blksize = 0
        self.index = 0
        self.sub = 0
        self.started = 0.0

    def send(self, data):
        self.bus.send(can.Message(arbitration_id=0x580 + self.node, data=bytes(data), is_extended_id=False))

    def sub_block(self):
        """Sends `blksize` block segments of 7 zero bytes, none of them the last."""
        for seqno in range(1, self.blksize + 1):
            self.send([seqno, 0, 0, 0, 0, 0, 0, 0])

    def on_request(self, data, timestamp):
        if len(data) < 8:
            return
        cmd = data[0]
        if cmd == 0x80:
            index, sub, code = struct.unpack_from("<HBI", data, 1)
            took = timestamp - self.started
            print(f"sdo_misbehave abort {code:08X} {index:04X}:{sub:02X} after {took:.3f}", flush=True)
            self.mode = None
            return
        if cmd == 0x40 or cmd & 0xE3 == 0xA0:  # initiate upload, block upload initiate
            self.started = timestamp
            self.index, self.sub = struct.unpack_from("<HB", data, 1)
            self.start(cmd, data)
        elif self.mode == "endless" and cmd & 0xEF == 0x60:  # upload segment request
            self.send([self.toggle, 1, 2, 3, 4, 5, 6, 7])
            self.toggle ^= 0x10
        elif self.mode == "block" and cmd in (0xA3, 0xA2):  # start, or a sub-block acknowledged
            if cmd == 0xA2:
                self.blksize = data[2] or self.blksize
            self.sub_block()

    def start(self, cmd, data):
        head = struct.pack("<HB", self.index, self.sub)
        self.toggle = 0
        if self.index == 0x2000 and cmd == 0x40:
            self.mode = "endless"
            self.send(bytes([0x41]) + head + struct.pack("<I", 10))
        elif self.index == 0x2001 and cmd == 0x40:
            self.send(bytes([0x4B]) + head[:2] + b"\x00")  # cut after the index: 4 bytes
        elif self.index == 0x2002 and cmd & 0xE3 == 0xA0:
            self.mode = "block"
            self.blksize = data[4]
            self.send(bytes([0xC4]) + head + bytes(4))  # no size, CRC supported
        elif self.index == 0x2004:
            self.send(bytes([0x60]) + head + bytes(4))  # a download response to an upload
        else:
            self.send(bytes([0x80]) + head + struct.pack("<I", 0x06020000))


def main():
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    iface, node = sys.argv[1], int(sys.argv[2], 0)
    bus = can.Bus(
        interface="socketcan",
        channel=iface,
        can_filters=[{"can_id": 0x600 + node, "can_mask": 0x7FF, "extended": False}],
    )
    stop = []
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
    signal.signal(signal.SIGINT, lambda *_: stop.append(1))
    server = Misbehave(bus, node)
    print(f"sdo_misbehave ready {iface} {node}", flush=True)
    try:
        while not stop:
            msg = bus.recv(timeout=0.2)
            if msg is not None and not msg.is_error_frame:
                server.on_request(msg.data, msg.timestamp)
    finally:
        bus.shutdown()


if __name__ == "__main__":
    main()
