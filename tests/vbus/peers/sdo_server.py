#!/usr/bin/env python3
"""A CANopen SDO server peer for end-to-end tests (canopen.LocalNode).

    python3 tests/vbus/peers/sdo_server.py IFACE NODE [--heartbeat-ms 1000] [--duration S]

Prints "sdo_server ready IFACE NODE" once it listens, sends its boot-up message and
heartbeats, and serves SDO (expedited, segmented and block transfers, see sdo_block.py)
until SIGTERM/SIGINT (or --duration seconds). Every value a client writes is printed as
"sdo_server wrote INDEX:SUB HEXBYTES" (what the python side stored). Its objects:

    0x1000 u32 0x00000191 ro      0x1008 visible string "vbus sdo peer"
    0x1017 u16 heartbeat ms rw    0x1018 identity record (sub 1..4)
    0x2000 u8  0x12 rw            0x2001 u16 0x1234 rw
    0x2002 u32 0x12345678 rw      0x2003 i32 -123456 rw
    0x2004 visible string "hello from vbus" rw
    0x2005 domain: bytes 0..255 repeated to 300 bytes, rw (exercises segmented/block SDO)
    0x2006 u32 0xCAFEF00D ro      (writing it aborts with 0x06010002)
"""

import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import canopen  # noqa: E402
from canopen import objectdictionary as odt  # noqa: E402

import common  # noqa: E402
import sdo_block  # noqa: E402

DOMAIN_BYTES = bytes(i % 256 for i in range(300))

OBJECTS = [
    (0x2000, "u8 value", odt.UNSIGNED8, 0x12, "rw"),
    (0x2001, "u16 value", odt.UNSIGNED16, 0x1234, "rw"),
    (0x2002, "u32 value", odt.UNSIGNED32, 0x12345678, "rw"),
    (0x2003, "i32 value", odt.INTEGER32, -123456, "rw"),
    (0x2004, "Greeting", odt.VISIBLE_STRING, "hello from vbus", "rw"),
    (0x2005, "Blob", odt.DOMAIN, DOMAIN_BYTES, "rw"),
    (0x2006, "Read-only u32", odt.UNSIGNED32, 0xCAFEF00D, "ro"),
]


def build_od(heartbeat_ms):
    """Return the peer's object dictionary (see the module doc for its content)."""
    od = odt.ObjectDictionary()
    common.comm_objects(od, heartbeat_ms, 0x00000191, "vbus sdo peer")
    for index, name, data_type, value, access in OBJECTS:
        od.add_object(common.var(index, 0, name, data_type, value, access))
    return od


def make_node(node_id, heartbeat_ms=1000):
    """Return an unconnected LocalNode with this peer's objects and block SDO support."""
    return sdo_block.use_block_sdo(canopen.LocalNode(node_id, build_od(heartbeat_ms)))


def print_write(index, subindex, od, data):
    """Print a value written by a client (a write callback of canopen.LocalNode)."""
    print(f"sdo_server wrote {index:04X}:{subindex:02X} {bytes(data).hex().upper()}", flush=True)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("iface")
    p.add_argument("node", type=common.auto_int)
    p.add_argument("--heartbeat-ms", type=int, default=1000)
    p.add_argument("--duration", type=float, default=None, help="stop after this many seconds")
    a = p.parse_args()
    node = make_node(a.node, a.heartbeat_ms)
    node.add_write_callback(print_write)
    network = common.start(node, a.iface)
    common.serve_until_signal(network, f"sdo_server ready {a.iface} {a.node}", a.duration)


if __name__ == "__main__":
    main()
