"""Two clients of `cotui serve` (port in argv[1]) while CAN FD frames cross the bus.

python-can's socketcand interface (4.6: classic frames only) and a raw socketcand client
speaking the CAN FD elements of socketcand PR #33. The test drives the order through
stdin/stdout lines, never through sleeps:
  prints "ready" once both clients receive the bus;
  waits for the `< fdframe 123 ... >` of the frame cotui's own client sends (prints it),
  then sends `< fdsend 0000ABCD 03 16 ... >` and a classic `< send 125 1 aa >` (for the
  other clients: a socketcand client does not get its own frames back);
  python-can reads on until 0x125 (prints what it made of the FD frames before it),
  then sends an FD message the way python-can writes it (prints whether the server answered
  with an error).
"""

import socket
import sys
import time

import can

port = int(sys.argv[1])


def say(*words):
    print(*words, flush=True)


class Raw:
    """A socketcand client in raw mode: elements as text."""

    def __init__(self):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=60)
        self.got = ""
        self.until("< hi >")
        self.sock.sendall(b"< open demo >")
        self.until("< ok >")
        self.sock.sendall(b"< rawmode >")
        self.until("< ok >")

    def until(self, start):
        """The next element starting with `start` (elements before it are skipped)."""
        end = time.time() + 60
        while time.time() < end:
            i = self.got.find(start)
            if i >= 0 and self.got.find(">", i) >= 0:
                j = self.got.find(">", i)
                element = self.got[i : j + 1]
                self.got = self.got[j + 1 :]
                return element
            self.got += self.sock.recv(4096).decode("ascii")
        raise TimeoutError(f"no {start} in {self.got[-400:]}")


bus = can.Bus(interface="socketcand", host="127.0.0.1", port=port, channel="demo")
raw = Raw()


def recv_until(pred, secs=60):
    """Messages python-can delivers up to the first that satisfies `pred` (included)."""
    seen = []
    end = time.time() + secs
    while time.time() < end:
        m = bus.recv(0.5)
        if m is not None:
            seen.append(m)
            if pred(m):
                return seen
    raise TimeoutError("python-can: no such message")


recv_until(lambda m: True)
raw.until("< frame ")
say("ready")

say("raw got", raw.until("< fdframe 123 "))
data = " ".join(f"{b:x}" for b in range(16))
raw.sock.sendall(f"< fdsend 0000ABCD 03 16 {data} >< send 125 1 aa >".encode("ascii"))

seen = recv_until(lambda m: m.arbitration_id == 0x125)
fd_like = [m for m in seen if m.is_fd or len(m.data) > 8 or m.arbitration_id in (0x123, 0xABCD)]
say("python-can got 125", seen[-1].data.hex(), "after", len(seen) - 1, "frames; fd frames delivered:", len(fd_like))

# python-can 4.6 writes an FD message as `< send 126 C ... >` (length in hex): not CAN FD in
# any socketcand dialect, so the server answers with an error and sends nothing.
bus.send(can.Message(arbitration_id=0x126, is_extended_id=False, is_fd=True, data=bytes(range(12))))
try:
    recv_until(lambda m: False, 30)
except can.CanError:
    # python-can cannot parse the server's `< error ... >` element and raises.
    say("python-can fd send: error from the server")
except TimeoutError:
    say("python-can fd send: no error")
bus.shutdown()
