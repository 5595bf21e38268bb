"""Loopback UDP helpers of the live tests: the port a recorder was given (``--port 0``), waiting until
a process holds a port or has read what was sent, and a sender paced to the receiver's socket buffer."""

from __future__ import annotations

import os
import re
import selectors
import time
from collections import deque
from pathlib import Path

import pytest

#: The tests that watch a recorder's socket read /proc/net/udp (Linux).
needs_proc_net_udp = pytest.mark.skipif(not Path("/proc/net/udp").exists(),
                                        reason="watches the recorder's UDP socket in /proc/net/udp (Linux only)")


#: what `physcam live record --port 0` says once it holds the port the system gave it
LISTENING = re.compile(rb"physcam: listening on UDP [0-9.]+:([0-9]+)\n")


def recorder_port(proc, timeout: float = 60.0) -> tuple[int, str]:
    """(the UDP port, what it said before) of ``proc``, a `physcam live record --port 0 ...` process
    started with ``stderr=subprocess.PIPE``: the port is the one its own socket holds, from its line
    "physcam: listening on UDP HOST:PORT" on standard error, said once it is bound. (A port picked
    here, closed and handed on, could be taken by another test's socket before the recorder bound
    it: the recorder then exited 2, "cannot listen".) The pipe is read a byte at a time from its file
    descriptor, nothing past that line, so ``proc.communicate()`` gets the rest. Raises RuntimeError,
    with what it said, when the recorder exits first; TimeoutError after ``timeout`` s."""
    fd, said = proc.stderr.fileno(), b""
    deadline = time.monotonic() + timeout
    with selectors.DefaultSelector() as sel:
        sel.register(fd, selectors.EVENT_READ)
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                proc.kill()
                raise TimeoutError(f"the recorder did not say its port in {timeout} s: {said.decode()!r}")
            if not sel.select(left):
                continue
            byte = os.read(fd, 1)
            if not byte:  # the pipe closed: the recorder has exited
                raise RuntimeError(f"the recorder exited ({proc.wait(timeout=60)}) before it listened: "
                                   f"{said.decode()!r}")
            said += byte
            start = said.rfind(b"\n", 0, len(said) - 1) + 1
            m = LISTENING.fullmatch(said, start) if byte == b"\n" else None
            if m:
                return int(m.group(1)), said[:start].decode()


def socket_inodes(pid: int) -> set[int]:
    """The inodes of the sockets process ``pid`` holds open (its /proc/PID/fd links ``socket:[N]``)."""
    out = set()
    for fd in Path(f"/proc/{pid}/fd").iterdir():
        try:
            link = os.readlink(fd)
        except OSError:  # closed meanwhile
            continue
        if link.startswith("socket:["):
            out.add(int(link[8:-1]))
    return out


def _udp_sockets(port: int) -> list[tuple[int, int]]:
    """(rx_queue bytes, inode) of each UDP socket bound to ``port``; empty if none is."""
    with open("/proc/net/udp") as f:  # sl, local_address ADDR:PORT, rem_address, st, tx_queue:rx_queue, .., inode
        rows = [line.split() for line in f.readlines()[1:]]
    return [(int(r[4].split(":")[1], 16), int(r[9])) for r in rows if r[1].endswith(f":{port:04X}")]


def udp_socket_inodes(port: int) -> set[int]:
    """The inodes of the UDP sockets bound to ``port`` (whichever process holds them)."""
    return {inode for _, inode in _udp_sockets(port)}


def _receive_queues(port: int) -> list[int]:
    """The bytes waiting (rx_queue) in each UDP socket bound to ``port``; empty if none is."""
    return [queue for queue, _ in _udp_sockets(port)]


def wait_until_read(proc, port: int, timeout: float = 60.0) -> None:
    """Until no datagram waits in the socket on UDP ``port`` (its rx_queue in /proc/net/udp), three
    reads 50 ms apart: the receiving process ``proc`` has read everything sent. Raises if it exits."""
    deadline, empty = time.monotonic() + timeout, 0
    while empty < 3:
        if proc.poll() is not None:
            raise RuntimeError(f"the recorder exited ({proc.returncode}) before reading what was sent")
        if time.monotonic() > deadline:
            raise TimeoutError(f"datagrams still wait on UDP port {port} after {timeout} s")
        queues = _receive_queues(port)
        empty = empty + 1 if queues and not any(queues) else 0
        time.sleep(0.05)


class PacedSender:
    """Send datagrams to an in-process Receiver as fast as it reads them, never more than a quarter of
    the socket buffer the kernel gave it in flight (sent, not yet counted "received"). UDP drops what
    overflows that buffer, and a stock kernel's net.core.rmem_max (212992) gives ~416 KiB, not the
    8 MiB asked for: unpaced, these tests lose datagrams there. Each datagram is charged 1 KiB of
    kernel overhead (skb truesize) besides its bytes."""

    OVERHEAD = 1024

    def __init__(self, tx, rx):
        self.tx, self.rx = tx, rx
        self.budget = rx.receive_buffer_granted_bytes // 4
        self._costs: deque[int] = deque()
        self._sent = self._acked = self._in_flight = 0

    def send(self, datagram: bytes, timeout: float = 30.0) -> None:
        cost = len(datagram) + self.OVERHEAD
        deadline = time.monotonic() + timeout
        while self._costs and self._in_flight + cost > self.budget:
            received = self.rx.counters()["received"]
            while self._acked < received and self._costs:
                self._in_flight -= self._costs.popleft()
                self._acked += 1
            if self._in_flight + cost > self.budget:
                if time.monotonic() > deadline:
                    raise TimeoutError(f"the receiver read {received} of {self._sent} datagrams in {timeout} s")
                time.sleep(0.0002)
        self.tx.send_datagram(datagram)
        self._costs.append(cost)
        self._in_flight += cost
        self._sent += 1
