"""SDO block upload and download (CiA 301 7.2.4.3.9-16) for canopen.LocalNode peers.

canopen's SdoServer answers a block upload with a normal upload and aborts a block
download; BlockSdoServer serves both as blocks, with the CRC (CRC-16/XMODEM) when the
client supports it. Install it with `use_block_sdo(node)` before the node joins a network.
"""

import binascii
import struct

from canopen.sdo.exceptions import SdoAbortedError
from canopen.sdo.server import SdoServer

BLKSIZE = 64  # segments per block offered to clients (1..127)
ABORT_INVALID_CS = 0x05040001
ABORT_INVALID_SEQNO = 0x05040003
ABORT_CRC = 0x05040004


class BlockSdoServer(SdoServer):
    """SdoServer with block upload/download; other transfers are canopen's."""

    def __init__(self, rx_cobid, tx_cobid, node):
        super().__init__(rx_cobid, tx_cobid, node)
        self._block = None  # None, "down" (receiving segments), "down-end", "up-start", "up"
        self._crc_ok = False

    def on_request(self, can_id, data, timestamp):
        # Idle, or the client aborts (0x80: a download segment never has seqno 0).
        if self._block is None or data[0] == 0x80:
            self._block = None
            return super().on_request(can_id, data, timestamp)
        try:
            if self._block == "down":
                self._down_segment(data)
            elif self._block == "down-end":
                self._down_end(data)
            else:
                self._up_step(data)
        except SdoAbortedError as e:
            self._block = None
            self.abort(e.code)

    # --- download: client -> server -------------------------------------------------
    def block_download(self, data):
        command, index, subindex = struct.unpack_from("<BHB", data)
        self._index, self._subindex = index, subindex
        if command & 0x01:  # cs must be "initiate"
            raise SdoAbortedError(ABORT_INVALID_CS)
        self._node._find_object(index, subindex)  # aborts for a missing object
        self._crc_ok = bool(command & 0x04)
        self._buffer = bytearray()
        self._seq = 0
        self._block = "down"
        self.send_response(struct.pack("<BHBB3x", 0xA4, index, subindex, BLKSIZE))

    def _down_segment(self, data):
        seqno = data[0] & 0x7F
        last = bool(data[0] & 0x80)
        if seqno == self._seq + 1:
            self._seq = seqno
            self._buffer.extend(data[1:8])
        # Out-of-order segments are dropped; the ack tells the client where to resume.
        if last or seqno >= BLKSIZE:
            self.send_response(struct.pack("<BBB5x", 0xA2, self._seq, BLKSIZE))
            if last and seqno == self._seq:
                self._block = "down-end"
            self._seq = 0

    def _down_end(self, data):
        if data[0] & 0xE3 != 0xC1:
            raise SdoAbortedError(ABORT_INVALID_CS)
        unused = (data[0] >> 2) & 0x07
        payload = bytes(self._buffer[: len(self._buffer) - unused])
        (crc,) = struct.unpack_from("<H", data, 1)
        if self._crc_ok and crc != binascii.crc_hqx(payload, 0):
            raise SdoAbortedError(ABORT_CRC)
        self._node.set_data(self._index, self._subindex, payload, check_writable=True)
        self._block = None
        self.send_response(struct.pack("<B7x", 0xA1))

    # --- upload: server -> client ---------------------------------------------------
    def block_upload(self, data):
        command, index, subindex, blksize = struct.unpack_from("<BHBB", data)
        self._index, self._subindex = index, subindex
        if command & 0x03:  # cs must be "initiate"
            raise SdoAbortedError(ABORT_INVALID_CS)
        if not 1 <= blksize <= 127:
            raise SdoAbortedError(0x05040002)
        self._payload = self._node.get_data(index, subindex, check_readable=True)
        self._blksize = blksize
        self._pos = 0  # first byte of the current block
        self._block = "up-start"
        self.send_response(struct.pack("<BHBL", 0xC6, index, subindex, len(self._payload)))

    def _up_step(self, data):
        cs = data[0]
        if self._block == "up-start" and cs & 0xE3 == 0xA3:
            self._block = "up"
            self._send_block()
        elif self._block == "up" and cs & 0xE3 == 0xA2:
            ackseq, blksize = data[1], data[2]
            self._pos = min(self._pos + 7 * ackseq, len(self._payload))
            self._blksize = blksize or self._blksize
            if self._pos >= len(self._payload) and self._sent_last(ackseq):
                unused = 7 - (len(self._payload) % 7 or 7) if self._payload else 7
                # Always the real CRC: we announce CRC support (sc), and a client that did not
                # ask for it ignores the field.
                crc = binascii.crc_hqx(self._payload, 0)
                self._block = "up-end"
                self.send_response(struct.pack("<BH5x", 0xC1 | (unused << 2), crc))
            else:
                self._send_block()
        elif self._block == "up-end" and cs & 0xE3 == 0xA1:
            self._block = None
        else:
            raise SdoAbortedError(ABORT_INVALID_CS)

    def _sent_last(self, ackseq):
        return ackseq == self._last_seq_sent and self._last_sent_final

    def _send_block(self):
        pos = self._pos
        seq = 0
        self._last_sent_final = False
        while seq < self._blksize:
            chunk = self._payload[pos : pos + 7]
            pos += 7
            seq += 1
            final = pos >= len(self._payload)
            self.send_response(bytes([seq | (0x80 if final else 0)]) + chunk.ljust(7, b"\x00"))
            if final:
                self._last_sent_final = True
                break
        self._last_seq_sent = seq


def use_block_sdo(node):
    """Replace `node`'s SDO server by a BlockSdoServer; call before network.add_node."""
    node.sdo = BlockSdoServer(node.sdo.rx_cobid, node.sdo.tx_cobid, node)
    return node
