#!/usr/bin/env python3
"""A canopen LocalNode built from an EDS, and the checks of `cotui dcf` against it.

    python3 dcf_node.py serve IFACE NODE EDS [--set INDEX:SUB=VALUE ...] --dump FILE
        Serves the EDS's objects (defaults resolved for NODE, then the --set values) by SDO.
        Prints "dcf_node ready IFACE NODE". On SIGUSR1 writes every readable value to FILE
        as JSON {"IIII:SS": "hex bytes"} and prints "dcf_node dumped N". SIGTERM ends it.
    python3 dcf_node.py check DCF NODE DUMP EDS OTHER_DUMP
        One python start-up for both checks (seconds under TCG):
        canopen.import_od(DCF, NODE): every value the node has (DUMP) must be in the DCF
        with the same value: prints "same N" or the differences;
        the writable values (per the EDS, commands 0x1010/0x1011 aside) of the two nodes'
        dumps are equal: prints "equal N" or the differences. Exit 0 when both hold.
"""

import argparse
import json
import os
import signal
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import canopen  # noqa: E402
from canopen import objectdictionary as odt  # noqa: E402

import common  # noqa: E402


def variables(od):
    """Every variable of `od` (record and array members included), dummies left out."""
    for obj in od.values():
        members = [obj] if isinstance(obj, odt.ODVariable) else list(obj.values())
        for v in members:
            if v.index >= 0x1000:
                yield v


def key(v):
    return f"{v.index:04X}:{v.subindex:02X}"


def dump(node, path):
    values = {}
    for v in variables(node.object_dictionary):
        if "r" not in v.access_type and v.access_type != "const":
            continue
        try:
            values[key(v)] = node.get_data(v.index, v.subindex, check_readable=True).hex()
        except Exception:  # noqa: BLE001 - an object without a value is not dumped
            pass
    with open(path + ".tmp", "w") as f:
        json.dump(values, f, indent=1, sort_keys=True)
    os.replace(path + ".tmp", path)
    print(f"dcf_node dumped {len(values)}", flush=True)


def serve(args):
    node = canopen.LocalNode(args.node, canopen.import_od(args.eds, args.node))
    for assignment in args.set:
        obj, value = assignment.split("=")
        index, sub = (int(x, 0) for x in obj.split(":"))
        v = node.object_dictionary[index]
        if not isinstance(v, odt.ODVariable):
            v = v[sub]
        node.set_data(index, sub, v.encode_raw(int(value, 0)), check_writable=False)
    signal.signal(signal.SIGUSR1, lambda *_: dump(node, args.dump))
    network = common.start(node, args.iface)
    common.serve_until_signal(network, f"dcf_node ready {args.iface} {args.node}")


def check_dcf(args):
    """The DCF holds the node's values (see the module doc); 0 when it does."""
    od = canopen.import_od(args.dcf, args.node)
    in_file = {key(v): v for v in variables(od) if v.value is not None}
    with open(args.dump) as f:
        node = json.load(f)
    bad, n = [], 0
    for k, hex_bytes in sorted(node.items()):
        index, sub = (int(x, 16) for x in k.split(":"))
        if index == 0x1003 and sub > 0:
            continue  # the error history past its count: no entries, not configuration
        n += 1
        v = in_file.get(k)
        if v is None:
            bad.append(f"{k} not in the DCF (node has {hex_bytes})")
        elif v.encode_raw(v.value).hex() != hex_bytes:
            bad.append(f"{k} {v.name}: DCF {v.value!r}, node {hex_bytes}")
    if bad:
        print("\n".join(bad))
        return 1
    print(f"same {n}")
    return 0


def check_equal(args):
    """The two dumps have the same writable values (see the module doc); 0 when they do."""
    od = canopen.import_od(args.eds, 1)
    with open(args.dump) as f:
        a = json.load(f)
    with open(args.other) as f:
        b = json.load(f)
    bad, n = [], 0
    for v in variables(od):
        if v.access_type not in ("rw", "rww", "rwr", "wo") or v.index in (0x1010, 0x1011):
            continue
        k = key(v)
        if a.get(k) != b.get(k):
            bad.append(f"{k} {v.name}: {a.get(k)} vs {b.get(k)}")
        n += 1
    if bad:
        print("\n".join(bad))
        return 1
    print(f"equal {n}")
    return 0


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    cmds = p.add_subparsers(dest="cmd", required=True)
    s = cmds.add_parser("serve")
    s.add_argument("iface")
    s.add_argument("node", type=common.auto_int)
    s.add_argument("eds")
    s.add_argument("--set", action="append", default=[])
    s.add_argument("--dump", required=True)
    c = cmds.add_parser("check")
    c.add_argument("dcf")
    c.add_argument("node", type=common.auto_int)
    c.add_argument("dump")
    c.add_argument("eds")
    c.add_argument("other")
    args = p.parse_args()
    if args.cmd == "serve":
        serve(args)
        return 0
    return check_dcf(args) | check_equal(args)


if __name__ == "__main__":
    sys.exit(main())
