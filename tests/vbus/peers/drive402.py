#!/usr/bin/env python3
"""A minimal CiA 402 drive peer for end-to-end tests (canopen.LocalNode).

    python3 tests/vbus/peers/drive402.py IFACE NODE [--heartbeat-ms 1000] [--tpdo]
                                         [--fault CODE] [--duration S]

Prints "drive402 ready IFACE NODE" once it listens; sends boot-up and heartbeats.
0x6040 controlword (rw) drives the CiA 402 state machine; 0x6041 statusword (ro) shows it:

    Switch on disabled 0x0250   Ready to switch on 0x0231   Switched on 0x0233
    Operation enabled  0x0237   Quick stop active  0x0217
    Fault 0x0218 (entered with voltage enabled) or 0x0208 (from Switch on disabled)

Commands (controlword masks per CiA 402): shutdown 0x06, switch on 0x07, enable operation
0x0F, disable operation 0x07 (from Operation enabled), disable voltage (bit 1 clear), quick
stop 0x02 (bit 2 clear), fault reset (bit 7 rising edge, in Fault). Writing a non-zero
error code to 0x2100 (or --fault CODE at start) enters Fault with that code in 0x603F.
0x6060 modes of operation (i8, rw) is mirrored in 0x6061. TPDO1 is sent on every statusword
change while NMT OPERATIONAL and on entering OPERATIONAL, when its COB-ID (0x1800:01) is
valid: with --tpdo it starts valid (0x180+NODE) and maps the statusword (2 bytes).

TPDO1 can be remapped (CiA 301): 0x1800:01 COB-ID, :02 transmission type, :03 inhibit time,
:05 event timer, 0x1A00:00 count and :01..:08 entries are writable; the frame follows the
mapping. Like many devices, it changes its mapping and transmission parameters only outside
NMT OPERATIONAL (abort 0x08000022 "present device state"), and refuses a count whose
entries exceed 64 bits (abort 0x06040042).
"""

import argparse
import os
import struct
import sys
import threading

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import canopen  # noqa: E402
from canopen import objectdictionary as odt  # noqa: E402

import common  # noqa: E402

SWITCH_ON_DISABLED = 0x0250
READY_TO_SWITCH_ON = 0x0231
SWITCHED_ON = 0x0233
OPERATION_ENABLED = 0x0237
QUICK_STOP_ACTIVE = 0x0217
FAULT = 0x0218
FAULT_NO_VOLTAGE = 0x0208

STATE_NAMES = {
    SWITCH_ON_DISABLED: "Switch on disabled",
    READY_TO_SWITCH_ON: "Ready to switch on",
    SWITCHED_ON: "Switched on",
    OPERATION_ENABLED: "Operation enabled",
    QUICK_STOP_ACTIVE: "Quick stop active",
    FAULT: "Fault",
    FAULT_NO_VOLTAGE: "Fault",
}


def next_state(state, controlword):
    """Return the statusword after `controlword` is written in `state` (CiA 402 table).

    Fault states are left only by a fault reset, which the caller detects (rising edge).
    """
    if state in (FAULT, FAULT_NO_VOLTAGE):
        return state
    if controlword & 0x0002 == 0:  # disable voltage
        return SWITCH_ON_DISABLED
    if controlword & 0x0004 == 0:  # quick stop
        return QUICK_STOP_ACTIVE if state == OPERATION_ENABLED else SWITCH_ON_DISABLED
    low = controlword & 0x000F
    if state == QUICK_STOP_ACTIVE:
        return OPERATION_ENABLED if low == 0x0F else state
    if low & 0x07 == 0x06:  # shutdown
        return READY_TO_SWITCH_ON
    if low == 0x07:  # switch on / disable operation
        return SWITCHED_ON if state in (READY_TO_SWITCH_ON, SWITCHED_ON, OPERATION_ENABLED) else state
    if low == 0x0F:  # enable operation (switch on + enable from Ready to switch on)
        return OPERATION_ENABLED if state in (READY_TO_SWITCH_ON, SWITCHED_ON, OPERATION_ENABLED) else state
    return state


def build_od(heartbeat_ms):
    """Return the drive's object dictionary."""
    od = odt.ObjectDictionary()
    common.comm_objects(od, heartbeat_ms, 0x00020192, "vbus drive402 peer")
    od.add_object(common.var(0x6040, 0, "Controlword", odt.UNSIGNED16, 0))
    od.add_object(common.var(0x6041, 0, "Statusword", odt.UNSIGNED16, SWITCH_ON_DISABLED, "ro"))
    od.add_object(common.var(0x603F, 0, "Error code", odt.UNSIGNED16, 0, "ro"))
    od.add_object(common.var(0x6060, 0, "Modes of operation", odt.INTEGER8, 0))
    od.add_object(common.var(0x6061, 0, "Modes of operation display", odt.INTEGER8, 0, "ro"))
    od.add_object(common.var(0x2100, 0, "Simulate fault (error code)", odt.UNSIGNED16, 0))
    tp = odt.ODRecord("TPDO1 communication parameter", 0x1800)
    tp.add_member(common.var(0x1800, 0, "Highest sub-index supported", odt.UNSIGNED8, 5, "const"))
    tp.add_member(common.var(0x1800, 1, "COB-ID", odt.UNSIGNED32, 0))
    tp.add_member(common.var(0x1800, 2, "Transmission type", odt.UNSIGNED8, 0xFF))
    tp.add_member(common.var(0x1800, 3, "Inhibit time", odt.UNSIGNED16, 0))
    tp.add_member(common.var(0x1800, 5, "Event timer", odt.UNSIGNED16, 0))
    od.add_object(tp)
    tm = odt.ODRecord("TPDO1 mapping parameter", 0x1A00)
    tm.add_member(common.var(0x1A00, 0, "Number of mapped objects", odt.UNSIGNED8, 1))
    for sub in range(1, 9):
        tm.add_member(common.var(0x1A00, sub, f"Mapping {sub}", odt.UNSIGNED32, 0x60410010 if sub == 1 else 0))
    od.add_object(tm)
    return od


class Drive:
    """A CiA 402 drive on a LocalNode: state machine, fault simulation, optional TPDO1."""

    def __init__(self, node_id, heartbeat_ms=1000, tpdo=False):
        self.node = canopen.LocalNode(node_id, build_od(heartbeat_ms))
        self.statusword = SWITCH_ON_DISABLED
        self.error_code = 0
        self.controlword = 0
        self.mode = 0
        self._lock = threading.Lock()
        # TPDO1 is disabled (bit 31) unless --tpdo.
        cob = 0x180 + node_id if tpdo else 0x80000180 + node_id
        self.node.data_store.setdefault(0x1800, {})[1] = struct.pack("<I", cob)
        self.node.add_read_callback(self._on_read)
        self.node.add_write_callback(self._on_write)

    def _on_read(self, index, subindex, od):
        if index == 0x6041:
            return self.statusword
        if index == 0x603F:
            return self.error_code
        if index == 0x6061:
            return self.mode
        if index == 0x1001:
            return 0x01 if self.statusword in (FAULT, FAULT_NO_VOLTAGE) else 0
        return None

    def _on_write(self, index, subindex, od, data):
        with self._lock:
            if index == 0x1A00 or (index == 0x1800 and subindex > 1):
                self._check_remap(index, subindex, data)
            if index == 0x6040:
                (cw,) = struct.unpack("<H", data)
                self._control(cw)
            elif index == 0x2100:
                (code,) = struct.unpack("<H", data)
                if code:
                    self.fault(code)
            elif index == 0x6060:
                (self.mode,) = struct.unpack("<b", data)

    def _control(self, cw):
        rising_reset = cw & 0x80 and not self.controlword & 0x80
        self.controlword = cw
        if self.statusword in (FAULT, FAULT_NO_VOLTAGE):
            if rising_reset:
                self.error_code = 0
                self._set(SWITCH_ON_DISABLED)
            return
        self._set(next_state(self.statusword, cw))

    def fault(self, code):
        """Enter Fault with error `code` in 0x603F."""
        self.error_code = code
        self._set(FAULT_NO_VOLTAGE if self.statusword == SWITCH_ON_DISABLED else FAULT)

    def _set(self, sw):
        changed = sw != self.statusword
        self.statusword = sw
        if changed:
            self.send_tpdo()

    def _check_remap(self, index, subindex, data):
        """Refuse TPDO1 parameter changes in OPERATIONAL, entries of objects this drive does
        not have, and mappings over 64 bits."""
        if self.node.nmt.state == "OPERATIONAL":
            raise canopen.SdoAbortedError(0x08000022)
        if index == 0x1A00 and subindex > 0:
            (e,) = struct.unpack("<I", bytes(data[:4]).ljust(4, b"\0"))
            if e and not self._has(e >> 16, (e >> 8) & 0xFF):
                raise canopen.SdoAbortedError(0x06040041)
        if index == 0x1A00 and subindex == 0:
            bits = sum(self._entry(k)[2] for k in range(1, data[0] + 1))
            if data[0] > 8 or bits > 64:
                raise canopen.SdoAbortedError(0x06040042)

    def _has(self, index, sub):
        """Whether the dictionary has (index, sub)."""
        try:
            obj = self.node.object_dictionary[index]
            if isinstance(obj, (odt.ODRecord, odt.ODArray)):
                obj[sub]
            return True
        except (KeyError, IndexError):
            return False

    def _entry(self, sub):
        (e,) = struct.unpack("<I", self.node.get_data(0x1A00, sub))
        return e >> 16, (e >> 8) & 0xFF, e & 0xFF

    def send_tpdo(self):
        """Send TPDO1 through its mapping when its COB-ID is valid and the node is OPERATIONAL."""
        (cob,) = struct.unpack("<I", self.node.get_data(0x1800, 1))
        if cob & 0x80000000 or self.node.nmt.state != "OPERATIONAL":
            return
        data = b""
        try:
            for index, sub, bits in (self._entry(k) for k in range(1, self.node.get_data(0x1A00, 0)[0] + 1)):
                data += self.node.get_data(index, sub)[: bits // 8]
        except Exception as e:  # noqa: BLE001 - say why in the peer's output (canopen only logs str(e))
            print(f"drive402: TPDO1 not sent: {e!r}", flush=True)
            return
        self.node.network.send_message(cob & 0x7FF, data)

    def attach(self, network):
        """Send TPDO1 on entering NMT OPERATIONAL (call after common.start)."""

        def on_nmt(can_id, data, timestamp):
            if len(data) >= 2 and data[0] == 0x01 and data[1] in (0, self.node.id):
                self.send_tpdo()

        network.subscribe(0, on_nmt)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("iface")
    p.add_argument("node", type=common.auto_int)
    p.add_argument("--heartbeat-ms", type=int, default=1000)
    p.add_argument("--tpdo", action="store_true", help="send TPDO1 with the statusword")
    p.add_argument("--fault", type=common.auto_int, default=0, help="start in Fault with this error code")
    p.add_argument("--duration", type=float, default=None, help="stop after this many seconds")
    a = p.parse_args()
    drive = Drive(a.node, a.heartbeat_ms, a.tpdo)
    if a.fault:
        drive.fault(a.fault)
    network = common.start(drive.node, a.iface)
    drive.attach(network)
    common.serve_until_signal(network, f"drive402 ready {a.iface} {a.node}", a.duration)


if __name__ == "__main__":
    main()
