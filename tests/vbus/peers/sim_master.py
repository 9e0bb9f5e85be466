"""The python `canopen` library as master against `cotui sim`: SDO (expedited, segmented,
block, abort), the CiA 402 state machine through BaseNode402, and LSS (fastscan, configure
node-ID, store, selective switch, inquire).

usage: sim_master.py IFACE EDS_DIR CHECK...
  CHECK: sdo | 402 | lss | vendor
Expects `cotui sim IFACE --node 2=aimotor --node ff=servo@0x99 --node ff=servo@0x1234
--write-eds EDS_DIR` on the bus (vendor: `--node 4=dexmart-dev --node 6=aqmd2405`, after
`cotui run IFACE 4 encoder_speed_m1` and `cotui run IFACE 6 rpdo_speed`). Prints one line per check: "ok <what>" or "FAIL <what>";
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


def vendor_checks(network, eds_dir):
    """The simulated Dexmart (node 4) and AQMD (node 6): their seed manuals' objects over SDO,
    and a Dexmart Multi-Drive command sent as a raw RPDO, answered by TPDO2."""
    dex = canopen.RemoteNode(4, f"{eds_dir}/node4.eds")
    aqmd = canopen.RemoteNode(6, f"{eds_dir}/node6.eds")
    for node in (dex, aqmd):
        network.add_node(node)
        node.sdo.RESPONSE_TIMEOUT = 3.0
    name = dex.sdo.upload(0x1008, 0).decode()
    check("dexmart: 0x1008 starts with DEV (the profile's identification)", name.startswith("DEV"), name)
    dyn = int.from_bytes(dex.sdo.upload(0x3000, 0x0A), "little")
    check("dexmart: Dynamic Data 10 = 2414 (manual: 581 4B 00 30 0A 6E 09)", dyn == 2414, dyn)
    check("dexmart: M1 at 3000 rpm after encoder_speed_m1 (0x3046:05)",
          wait_until(lambda: dex.sdo[0x3046][5].raw == 3000, 5), dex.sdo[0x3046][5].raw)
    replies = []
    network.subscribe(0x284, lambda can_id, data, ts: replies.append(bytes(data)))
    dex.sdo[0x3001][27].raw = 2  # 01-27 = 2: M2 in an encoder mode
    network.send_message(0x304, bytes([0x0F, 100, 0, 0, 0]))  # RPDO2: CMD 0Fh, position 100
    check("dexmart: RPDO2 position command answered by TPDO2 (0x284)", wait_until(lambda: replies, 3), replies)
    check("dexmart: M2 encoder position reaches 100 (0x304A:17)",
          wait_until(lambda: dex.sdo[0x304A][23].raw == 100, 5), dex.sdo[0x304A][23].raw)
    device_type = int.from_bytes(aqmd.sdo.upload(0x1000, 0), "little")
    check("aqmd: device type 0 (no CiA profile)", device_type == 0, device_type)
    check("aqmd: duty 100.0 % after rpdo_speed (0x2101)",
          wait_until(lambda: aqmd.sdo[0x2101].raw == 1000, 5), aqmd.sdo[0x2101].raw)
    aqmd.sdo[0x2000].raw = 0
    check("aqmd: control command 0 by SDO stops it (0x2101 = 0)",
          wait_until(lambda: aqmd.sdo[0x2101].raw == 0, 5), aqmd.sdo[0x2101].raw)


def main():
    iface, eds_dir, checks = sys.argv[1], sys.argv[2], sys.argv[3:]
    network = canopen.Network()
    network.connect(channel=iface, interface="socketcan")
    try:
        for c in checks:
            try:
                {"sdo": lambda: sdo_checks(network, eds_dir),
                 "402": lambda: drive_checks(network, eds_dir),
                 "lss": lambda: lss_checks(network),
                 "vendor": lambda: vendor_checks(network, eds_dir)}[c]()
            except Exception as e:  # a check that raises is a failure with its reason
                fail(f"{c}: {type(e).__name__}: {e}")
    finally:
        network.disconnect()
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
