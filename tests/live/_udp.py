"""Loopback UDP helpers of the live tests: a free port, and waiting until a recorder holds one."""

from __future__ import annotations

import socket
import time


def free_port() -> int:
    """A UDP port on 127.0.0.1 that nothing holds now."""
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def wait_for_port(proc, port: int, timeout: float = 60.0) -> None:
    """Until the process ``proc`` (a recorder) holds UDP ``port``, or it exits, or ``timeout`` s pass."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and proc.poll() is None:
        with open("/proc/net/udp") as f:  # local_address is ADDR:PORT in hex
            if any(line.split()[1].endswith(f":{port:04X}") for line in f.readlines()[1:]):
                return
        time.sleep(0.1)
