"""Start `physcam serve` as a real process on a free loopback port, and talk HTTP to it."""

from __future__ import annotations

import http.client
import json
import os
import re
import subprocess
import sys
import threading
import time
from contextlib import contextmanager

URL_LINE = re.compile(r"listening on (http://127\.0\.0\.1:(\d+)/)")


@contextmanager
def running_server(*flags: str, timeout: float = 90.0, env: dict | None = None):
    """`physcam serve --port 0 FLAGS...` in a subprocess (``env``: variables added to its environment);
    yields (base URL, port, the process)."""
    env = dict(os.environ, PYTHONUNBUFFERED="1", **(env or {}))
    proc = subprocess.Popen([sys.executable, "-m", "physcam", "serve", "--port", "0", *flags],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    lines: list[str] = []
    found = threading.Event()
    match: list = []

    def read():
        for line in proc.stdout:
            lines.append(line)
            m = URL_LINE.search(line)
            if m and not match:
                match.append(m)
                found.set()

    errors: list[str] = []

    def drain():  # the server's standard error, kept for the tests (and never left to fill its pipe)
        for line in proc.stderr:
            errors.append(line)

    proc.stderr_lines = errors
    threading.Thread(target=read, daemon=True).start()
    threading.Thread(target=drain, daemon=True).start()
    try:
        if not found.wait(timeout):
            proc.kill()
            raise RuntimeError(f"physcam serve did not start: {''.join(lines)} {''.join(errors)[-2000:]}")
        url, port = match[0].group(1), int(match[0].group(2))
        _wait_until_up(port)
        yield url, port, proc
    finally:
        if proc.poll() is None:
            proc.terminate()
            try:
                proc.wait(timeout=15)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()


def _wait_until_up(port: int, timeout: float = 30.0):
    t0 = time.monotonic()
    while True:
        try:
            status, _, _ = request(port, "/api/health")
            if status == 200:
                return
        except OSError:
            pass
        if time.monotonic() - t0 > timeout:
            raise RuntimeError("physcam serve does not answer /api/health")
        time.sleep(0.1)


def request(port: int, path: str, *, method: str = "GET", body: bytes | None = None, headers=None, timeout=60):
    """(status, headers dict, body bytes) of one request on a fresh connection."""
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=timeout)
    try:
        c.request(method, path, body=body, headers=headers or {})
        r = c.getresponse()
        return r.status, {k.lower(): v for k, v in r.getheaders()}, r.read()
    finally:
        c.close()


def get_json(port: int, path: str):
    status, headers, body = request(port, path)
    return status, json.loads(body)
