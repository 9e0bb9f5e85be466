#!/usr/bin/env python3
# Writes an unsorted MDF4 bus-logging file by hand (asammdf and python-can write sorted ones):
# usage: unsorted.py OUT FRAMES_JSON, frames as [time_us, channel, id, ext, fd, brs, tx, hex].
import struct, sys
# A CANedge-shaped MDF 4.11 file: one unsorted data group, a CAN_DataFrame group (u64 time
# in microseconds through a linear conversion, ID with bit 31 for 29-bit ids, payload as
# VLSD records of a second group) and its VLSD group, records interleaved in one ##DT.
out = bytearray(b"MDF     4.11    cotui   " + b"\0" * 4 + struct.pack("<H", 411) + b"\0" * 34)
def block(bid, links, data):
    global out
    at = len(out)
    body = struct.pack("<4s4xQQ", bid, 24 + 8 * len(links) + len(data), len(links))
    body += b"".join(struct.pack("<Q", l) for l in links) + data
    out += body + b"\0" * (-len(body) % 8)
    return at
def patch(at, i, value):
    struct.pack_into("<Q", out, at + 24 + 8 * i, value)
def tx(s):
    return block(b"##TX", [], s.encode() + b"\0")
hd = block(b"##HD", [0] * 6, struct.pack("<QhhBBBBdd", 1700000000 * 10**9, 0, 0, 0, 0, 0, 0, 0.0, 0.0))
def cn(name, cn_type, sync, dtype, byte, bits, composition=0, conv=0, data=0):
    return block(b"##CN", [0, composition, tx(name), 0, conv, data, 0, 0],
                 struct.pack("<BBBBIIIIBBH6d", cn_type, sync, dtype, 0, byte, bits, 0, 0, 0, 0, 0, *[0.0] * 6))
dg = block(b"##DG", [0, 0, 0, 0], struct.pack("<B7x", 1))
vlsd_cg = block(b"##CG", [0, 0, 0, 0, 0, 0], struct.pack("<QQHH4xII", 2, 0, 1, 0, 0, 0))
cc = block(b"##CC", [0, 0, 0, 0], struct.pack("<BBHHHdddd", 1, 0, 0, 0, 2, 0.0, 0.0, 0.0, 1e-6))
# Record after its id: time u64 @0, BusChannel @8, ID u32 @9, IDE @13, DLC @14, DataLength @15,
# Dir @16, EDL @17, BRS @18, DataBytes (u64 VLSD offset) @19: 27 bytes.
members = [("BusChannel", 0, 8, 8), ("ID", 0, 9, 32), ("IDE", 0, 13, 8), ("DLC", 0, 14, 8),
           ("DataLength", 0, 15, 8), ("Dir", 0, 16, 8), ("EDL", 0, 17, 8), ("BRS", 0, 18, 8)]
chain = [cn("CAN_DataFrame." + n, t, 0, 0, b, bits) for n, t, b, bits in members]
chain.append(cn("CAN_DataFrame.DataBytes", 1, 0, 10, 19, 64, data=vlsd_cg))
for a, b in zip(chain, chain[1:]):
    patch(a, 0, b)
frame = cn("CAN_DataFrame", 0, 0, 10, 8, 19 * 8, composition=chain[0])
time = cn("Timestamp", 2, 1, 0, 0, 64, conv=cc)
patch(time, 0, frame)
cg = block(b"##CG", [vlsd_cg, time, tx("CAN_DataFrame"), 0, 0, 0], struct.pack("<QQHH4xII", 1, 0, 0, 0, 27, 0))
patch(dg, 1, cg)
records = bytearray()
offset = 0
import json
for t, ch, i, ext, fd, brs, tx_, data in json.loads(sys.argv[2]):
    data = bytes.fromhex(data)
    records += struct.pack("<BI", 2, len(data)) + data
    dlc = [0,1,2,3,4,5,6,7,8,12,16,20,24,32,48,64].index(len(data)) if fd else len(data)
    records += struct.pack("<BQBIBBBBBBQ", 1, t, ch, i | (ext << 31), ext, dlc, len(data), tx_, fd, brs, offset)
    offset += 4 + len(data)
n = len(json.loads(sys.argv[2]))
struct.pack_into("<Q", out, cg + 72 + 8, n)
struct.pack_into("<QHH4xQ", out, vlsd_cg + 72 + 8, n, 1, 0, offset)
dt = block(b"##DT", [], bytes(records))
patch(dg, 2, dt)
patch(hd, 0, dg)
open(sys.argv[1], "wb").write(out)
