#!/usr/bin/env python3
"""A CANopen node that fails, for the live diagnosis end-to-end check (standard library only:
a raw SocketCAN socket starts in a fraction of the time python-can or canopen take in the
TCG guest).

    python3 tests/vbus/peers/diag_node.py IFACE NODE [--heartbeat-ms 100] [--beats 10]
                                          [--emcy CODE] [--after-s 3]

Prints "diag_node ready IFACE NODE" once its socket is open, then sends a boot-up, heartbeats
(Operational) every --heartbeat-ms, after --beats of them one EMCY with error code --emcy
(error register 0x01, manufacturer bytes 0), --beats more heartbeats, and then goes silent
(as a crashed device does). Exits --after-s seconds after the last heartbeat, printing
"diag_node silent IFACE NODE after N heartbeats" when it stops beating.
"""

import argparse
import socket
import struct
import sys
import time

CAN_FRAME = struct.Struct("=IB3x8s")


def auto_int(text):
    return int(text, 0)


def send(sock, cob_id, data):
    sock.send(CAN_FRAME.pack(cob_id, len(data), bytes(data).ljust(8, b"\0")))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("iface")
    p.add_argument("node", type=auto_int)
    p.add_argument("--heartbeat-ms", type=int, default=100)
    p.add_argument("--beats", type=int, default=10, help="heartbeats before and after the EMCY")
    p.add_argument("--emcy", type=auto_int, default=0x3210, help="EMCY error code")
    p.add_argument("--after-s", type=float, default=3.0, help="seconds to stay silent before exiting")
    a = p.parse_args()
    sock = socket.socket(socket.AF_CAN, socket.SOCK_RAW, socket.CAN_RAW)
    sock.bind((a.iface,))
    print(f"diag_node ready {a.iface} {a.node}", flush=True)
    period = a.heartbeat_ms / 1000.0
    send(sock, 0x700 + a.node, [0x00])
    beats = 0
    start = time.monotonic()
    for i in range(2 * a.beats):
        # Paced by the schedule, not by the sleeps: a late wake-up does not drift.
        time.sleep(max(0.0, start + (i + 1) * period - time.monotonic()))
        send(sock, 0x700 + a.node, [0x05])
        beats += 1
        if beats == a.beats:
            send(sock, 0x80 + a.node, list(struct.pack("<HB5x", a.emcy, 0x01)))
    print(f"diag_node silent {a.iface} {a.node} after {beats} heartbeats", flush=True)
    time.sleep(a.after_s)
    return 0


if __name__ == "__main__":
    sys.exit(main())
