"""Shared plumbing for the vbus CANopen peers: object dictionary helpers and NMT start-up."""

import signal
import threading

import canopen
from canopen import objectdictionary as odt

BOOTUP_STATE = "PRE-OPERATIONAL"


def var(index, subindex, name, data_type, value, access="rw"):
    """Return an OD variable of `data_type` holding `value` (default and current)."""
    v = odt.ODVariable(name, index, subindex)
    v.data_type = data_type
    v.access_type = access
    v.default = value
    v.value = value
    return v


def comm_objects(od, heartbeat_ms, device_type, device_name):
    """Add the CiA 301 objects every peer has: 0x1000, 0x1001, 0x1008, 0x1017, 0x1018."""
    od.add_object(var(0x1000, 0, "Device type", odt.UNSIGNED32, device_type, "ro"))
    od.add_object(var(0x1001, 0, "Error register", odt.UNSIGNED8, 0, "ro"))
    od.add_object(var(0x1008, 0, "Manufacturer device name", odt.VISIBLE_STRING, device_name, "const"))
    od.add_object(var(0x1017, 0, "Producer heartbeat time", odt.UNSIGNED16, heartbeat_ms))
    ident = odt.ODRecord("Identity object", 0x1018)
    ident.add_member(var(0x1018, 0, "Highest sub-index supported", odt.UNSIGNED8, 4, "const"))
    for sub, (name, value) in enumerate(
        [("Vendor-ID", 0x00000F00), ("Product code", 0x0000402), ("Revision number", 0x00010001), ("Serial number", 7)],
        start=1,
    ):
        ident.add_member(var(0x1018, sub, name, odt.UNSIGNED32, value, "ro"))
    od.add_object(ident)


def start(node, channel, interface="socketcan"):
    """Connect `node` to a bus, send its boot-up message and enter PRE-OPERATIONAL.

    Heartbeats start with the period in 0x1017. An NMT reset command received later makes
    the node send boot-up again and return to PRE-OPERATIONAL, as a real device does.
    Returns the connected canopen.Network.
    """
    network = canopen.Network()
    network.connect(channel=channel, interface=interface)
    network.add_node(node)

    def on_nmt(can_id, data, timestamp):
        if len(data) >= 2 and data[0] in (0x81, 0x82) and data[1] in (0, node.id):
            node.nmt.state = "RESET COMMUNICATION"
            node.nmt.state = BOOTUP_STATE

    network.subscribe(0, on_nmt)
    node.nmt.state = "RESET COMMUNICATION"  # state 0: sends the boot-up message
    node.nmt.state = BOOTUP_STATE  # starts the heartbeat from 0x1017
    return network


def serve_until_signal(network, ready_line, duration=None):
    """Print `ready_line` (flushed) and serve until SIGTERM/SIGINT or `duration` seconds."""
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    signal.signal(signal.SIGINT, lambda *_: stop.set())
    print(ready_line, flush=True)
    stop.wait(duration)
    network.disconnect()


def auto_int(text):
    """argparse type accepting decimal or 0x-prefixed integers."""
    return int(text, 0)
