"""Loopback UDP helpers of the live tests: a free port, waiting until a recorder holds one, and a
sender paced to the receiver's socket buffer."""

from __future__ import annotations

import socket
import time
from collections import deque
from pathlib import Path

import pytest

#: The tests that watch a recorder's socket read /proc/net/udp (Linux).
needs_proc_net_udp = pytest.mark.skipif(not Path("/proc/net/udp").exists(),
                                        reason="watches the recorder's UDP socket in /proc/net/udp (Linux only)")


def free_port() -> int:
    """A UDP port on 127.0.0.1 that nothing holds now."""
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def _receive_queues(port: int) -> list[int]:
    """The bytes waiting (rx_queue) in each UDP socket bound to ``port``; empty if none is."""
    with open("/proc/net/udp") as f:  # local_address is ADDR:PORT, then rem_address, st, tx_queue:rx_queue
        rows = [line.split() for line in f.readlines()[1:]]
    return [int(r[4].split(":")[1], 16) for r in rows if r[1].endswith(f":{port:04X}")]


def wait_for_port(proc, port: int, timeout: float = 60.0) -> None:
    """Until the process ``proc`` (a recorder) holds UDP ``port``, or it exits, or ``timeout`` s pass."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and proc.poll() is None:
        if _receive_queues(port):
            return
        time.sleep(0.1)


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
