"""The python `canopen` library as master against `cotui sim`: SDO (expedited, segmented,
block, abort), the CiA 402 state machine through BaseNode402, and LSS (fastscan, configure
node-ID, store, selective switch, inquire).

usage: sim_master.py IFACE EDS_DIR CHECK...
  CHECK: sdo | 402 | lss
Expects `cotui sim IFACE --node 2=aimotor --node ff=servo@0x99 --node ff=servo@0x1234
--write-eds EDS_DIR` on the bus. Prints one line per check: "ok <what>" or "FAIL <what>";
exits 1 on any failure.
"""

import sys
import time

import canopen
from canopen.lss import LssMaster
from canopen.profiles.p402 import BaseNode402

failures = 0


def ok(what):
    print(f"ok {what}", flush=True)


def fail(what):
    global failures
    failures += 1
    print(f"FAIL {what}", flush=True)


def check(what, cond, detail=""):
    (ok if cond else fail)(what if cond else f"{what}: {detail}")


def wait_until(cond, seconds):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if cond():
            return True
        time.sleep(0.05)
    return cond()


def sdo_checks(network, eds_dir):
    node = canopen.RemoteNode(2, f"{eds_dir}/node2.eds")
    network.add_node(node)
    node.sdo.RESPONSE_TIMEOUT = 3.0
    serial = node.sdo.upload(0x1018, 4)
    check("sdo expedited upload 0x1018:04 = 1002", int.from_bytes(serial, "little") == 1002, serial.hex())
    name = node.sdo.upload(0x1008, 0).decode()
    check("sdo segmented upload 0x1008 (device name)", name.startswith("cotui simulated"), name)
    with node.sdo.open(0x1008, 0, "rb", block_transfer=True) as f:
        block = f.read()
    check("sdo block upload 0x1008 gives the same bytes", block.decode() == name, block)
    node.sdo[0x6060].raw = 3
    check("sdo download 0x6060 = 3, read back", node.sdo[0x6060].raw == 3, node.sdo[0x6060].raw)
    try:
        node.sdo.download(0x1018, 1, b"\x00\x00\x00\x00")
        fail("sdo write to read-only 0x1018:01 must abort")
    except canopen.SdoAbortedError as e:
        check("sdo write to read-only 0x1018:01 aborts 0x06010002", e.code == 0x06010002, hex(e.code))
    network.nodes.pop(2, None)


def drive_checks(network, eds_dir):
    node = BaseNode402(2, f"{eds_dir}/node2.eds")
    network.add_node(node)
    node.sdo.RESPONSE_TIMEOUT = 3.0
    node.TIMEOUT_SWITCH_STATE_FINAL = 30
    node.TIMEOUT_SWITCH_STATE_SINGLE = 10
    node.nmt.state = "PRE-OPERATIONAL"
    node.setup_402_state_machine()
    node.nmt.state = "OPERATIONAL"
    network.sync.start(0.02)
    try:
        node.state = "OPERATION ENABLED"
        check("BaseNode402 takes the drive to OPERATION ENABLED", node.state == "OPERATION ENABLED", node.state)
        sw = node.sdo[0x6041].raw
        check("statusword read by SDO shows operation enabled (0x..37)", sw & 0x6F == 0x27, hex(sw))
        node.state = "SWITCH ON DISABLED"
        check("BaseNode402 takes it back to SWITCH ON DISABLED", node.state == "SWITCH ON DISABLED", node.state)
    finally:
        network.sync.stop()
        node.nmt.state = "PRE-OPERATIONAL"
    network.nodes.pop(2, None)


def lss_checks(network):
    lss = network.lss
    lss.RESPONSE_TIMEOUT = 1.0
    lss.send_switch_state_global(lss.WAITING_STATE)
    found, ident = lss.fast_scan()
    check("LSS fastscan finds the non-configured node with the lowest address (serial 0x99)",
          found and ident is not None and ident[3] == 0x99, ident)
    # The found node is in configuration state now.
    lss.configure_node_id(10)
    lss.store_configuration()
    ok("LSS configure node-ID 10 and store configuration confirmed")
    lss.send_switch_state_global(lss.WAITING_STATE)
    booted = []
    network.subscribe(0x70A, lambda can_id, data, ts: booted.append(bytes(data)))
    network.nmt.send_command(0x82)  # reset communication: the pending node-ID comes into use
    check("after reset communication the node boots up as node 10", wait_until(lambda: b"\x00" in booted, 5), booted)
    node10 = network.add_node(10)
    node10.sdo.RESPONSE_TIMEOUT = 3.0
    serial = int.from_bytes(node10.sdo.upload(0x1018, 4), "little")
    check("node 10 answers SDO with serial 0x99", serial == 0x99, hex(serial))
    # Selective switch to the other one by its full address, then inquire.
    vendor, product, revision = ident[0], ident[1], ident[2]
    lss.send_switch_state_selective(vendor, product, revision, 0x1234)
    node_id = lss.inquire_node_id()
    check("LSS selective switch + inquire node-ID: the other node has none (0xFF)", node_id == 0xFF, node_id)
    serial = lss.inquire_lss_address(0x5D)
    check("LSS inquire serial number = 0x1234", serial == 0x1234, hex(serial))
    lss.send_switch_state_global(lss.WAITING_STATE)


def main():
    iface, eds_dir, checks = sys.argv[1], sys.argv[2], sys.argv[3:]
    network = canopen.Network()
    network.connect(channel=iface, interface="socketcan")
    try:
        for c in checks:
            try:
                {"sdo": lambda: sdo_checks(network, eds_dir),
                 "402": lambda: drive_checks(network, eds_dir),
                 "lss": lambda: lss_checks(network)}[c]()
            except Exception as e:  # a check that raises is a failure with its reason
                fail(f"{c}: {type(e).__name__}: {e}")
    finally:
        network.disconnect()
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
