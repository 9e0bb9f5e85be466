#!/usr/bin/env python3
"""Tests of the vbus peers with python-can/canopen clients; runs in the vbus guest.

    python3 tests/vbus/peers/test_peers.py [IFACE]      (default vcan0)

Servers and clients share one process (one interpreter start-up: seconds under TCG) and
talk over the kernel's vcan. Prints one line per check and "N passed, N failed".
"""

import os
import struct
import sys
import time
import traceback

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import can  # noqa: E402
import canopen  # noqa: E402

import common  # noqa: E402
import drive402  # noqa: E402
import sdo_server  # noqa: E402

IFACE = sys.argv[1] if len(sys.argv) > 1 else "vcan0"
SDO_NODE = 0x21
DRIVE_NODE = 0x22
CHECKS = []


def check(fn):
    """Register a check."""
    CHECKS.append(fn)
    return fn


def expect(got, want, what):
    if got != want:
        raise AssertionError(f"{what}: got {got!r}, want {want!r}")


class Bus:
    """A raw python-can socket on the interface, for frame-level checks."""

    def __init__(self):
        self.bus = can.Bus(channel=IFACE, interface="socketcan")

    def wait_for(self, can_id, timeout=5.0, pred=lambda m: True):
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            m = self.bus.recv(end - time.monotonic())
            if m is not None and m.arbitration_id == can_id and pred(m):
                return m
        raise AssertionError(f"no frame 0x{can_id:03X} within {timeout}s")


MON = None
CLIENT = None
SDO = None
DRIVE = None


@check
def bootup_and_heartbeat():
    # Boot-up (0x700+id, 00) when the node starts, then heartbeats with state 0x7F.
    node = sdo_server.make_node(0x25, heartbeat_ms=100)
    net = common.start(node, IFACE)
    try:
        MON.wait_for(0x725, pred=lambda m: bytes(m.data) == b"\x00")
        MON.wait_for(0x725, pred=lambda m: bytes(m.data) == b"\x7f")
    finally:
        net.disconnect()


@check
def sdo_expedited_reads():
    expect(SDO.sdo.upload(0x2000, 0), b"\x12", "u8")
    expect(SDO.sdo.upload(0x2001, 0), struct.pack("<H", 0x1234), "u16")
    expect(SDO.sdo.upload(0x2002, 0), struct.pack("<I", 0x12345678), "u32")
    expect(SDO.sdo.upload(0x2003, 0), struct.pack("<i", -123456), "i32")
    expect(SDO.sdo.upload(0x1018, 1), struct.pack("<I", 0xF00), "vendor id")


@check
def sdo_segmented_read_string():
    expect(SDO.sdo.upload(0x1008, 0), b"vbus sdo peer", "device name")
    expect(SDO.sdo.upload(0x2004, 0), b"hello from vbus", "greeting")


@check
def sdo_expedited_write_then_read():
    SDO.sdo.download(0x2002, 0, struct.pack("<I", 0xDEADBEEF))
    expect(SDO.sdo.upload(0x2002, 0), struct.pack("<I", 0xDEADBEEF), "u32 after write")
    SDO.sdo.download(0x2003, 0, struct.pack("<i", -1))
    expect(SDO.sdo.upload(0x2003, 0), b"\xff\xff\xff\xff", "i32 after write")


@check
def sdo_segmented_write_domain():
    data = bytes(range(100, 200))
    SDO.sdo.download(0x2005, 0, data, force_segment=True)
    expect(SDO.sdo.upload(0x2005, 0), data, "domain after segmented write")


@check
def sdo_block_upload_domain():
    for data in (sdo_server.DOMAIN_BYTES, bytes(i % 251 for i in range(1000))):  # 1 and 2 blocks
        SDO.sdo.download(0x2005, 0, data)
        with SDO.sdo.open(0x2005, 0, "rb", block_transfer=True) as f:
            got = f.read()
        expect(got, data, f"{len(data)} bytes by block upload")


@check
def sdo_block_download_domain():
    data = bytes((i * 7) % 256 for i in range(1000))  # several blocks of 64 segments
    with SDO.sdo.open(0x2005, 0, "wb", size=len(data), block_transfer=True) as f:
        f.write(data)
    expect(SDO.sdo.upload(0x2005, 0), data, "domain after block download")


@check
def sdo_aborts():
    for index, code in [(0x2006, 0x06010002), (0x2FFF, 0x06020000)]:
        try:
            SDO.sdo.download(index, 0, b"\x00\x00\x00\x00")
        except canopen.SdoAbortedError as e:
            expect(e.code, code, f"abort code for 0x{index:04X}")
        else:
            raise AssertionError(f"write to 0x{index:04X} was not aborted")


def sw():
    return struct.unpack("<H", DRIVE.sdo.upload(0x6041, 0))[0]


def cw(value):
    DRIVE.sdo.download(0x6040, 0, struct.pack("<H", value))


@check
def drive_enable_sequence_and_tpdo():
    expect(sw(), 0x0250, "initial statusword")
    CLIENT.nmt.send_command(0x01)  # NMT start all: TPDO1 allowed
    MON.wait_for(0x180 + DRIVE_NODE, pred=lambda m: bytes(m.data) == b"\x50\x02")
    for control, status in [(0x06, 0x0231), (0x07, 0x0233), (0x0F, 0x0237)]:
        cw(control)
        expect(sw(), status, f"statusword after controlword 0x{control:04X}")
        MON.wait_for(0x180 + DRIVE_NODE, pred=lambda m, s=status: bytes(m.data) == struct.pack("<H", s))
    cw(0x07)
    expect(sw(), 0x0233, "disable operation")
    cw(0x0F)
    cw(0x02)
    expect(sw(), 0x0217, "quick stop active")
    cw(0x00)
    expect(sw(), 0x0250, "disable voltage from quick stop")


@check
def drive_fault_and_reset():
    cw(0x06)
    expect(sw(), 0x0231, "ready to switch on")
    DRIVE.sdo.download(0x2100, 0, struct.pack("<H", 0x7500))
    expect(sw(), 0x0218, "fault with voltage")
    expect(DRIVE.sdo.upload(0x603F, 0), struct.pack("<H", 0x7500), "error code")
    cw(0x0F)
    expect(sw(), 0x0218, "fault ignores enable")
    cw(0x80)
    expect(sw(), 0x0250, "fault reset on rising edge")
    expect(DRIVE.sdo.upload(0x603F, 0), b"\x00\x00", "error code cleared")
    DRIVE.sdo.download(0x2100, 0, struct.pack("<H", 0x2310))
    expect(sw(), 0x0208, "fault from switch on disabled")
    cw(0x80)
    expect(sw(), 0x0208, "no reset without a rising edge")
    cw(0x00)
    cw(0x80)
    expect(sw(), 0x0250, "reset after 0 -> 0x80")


def main():
    global MON, CLIENT, SDO, DRIVE
    MON = Bus()
    server = sdo_server.make_node(SDO_NODE)
    net_s = common.start(server, IFACE)
    drive = drive402.Drive(DRIVE_NODE, tpdo=True)
    net_d = common.start(drive.node, IFACE)
    drive.attach(net_d)
    CLIENT = canopen.Network()
    CLIENT.connect(channel=IFACE, interface="socketcan")
    SDO = CLIENT.add_node(SDO_NODE, canopen.ObjectDictionary())
    DRIVE = CLIENT.add_node(DRIVE_NODE, canopen.ObjectDictionary())
    passed = failed = 0
    for fn in CHECKS:
        try:
            fn()
        except Exception:
            failed += 1
            print(f"FAIL {fn.__name__}\n{traceback.format_exc()}", flush=True)
        else:
            passed += 1
            print(f"ok   {fn.__name__}", flush=True)
    for n in (CLIENT, net_s, net_d):
        n.disconnect()
    MON.bus.shutdown()
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
