"""Benchmark: `physcam serve`'s CPU per request, this tree against another, side by side (issue 47).

    .venv/bin/python benchmarks/serve_cpu.py --baseline /tmp/main/src [--blocks 10] [--size 400]

Two servers run at once, this tree's and the baseline's (``--baseline``: a ``src`` folder, e.g. from
``git archive main src``, run with PYTHONPATH). Each takes the same requests in blocks, closed loop
on 4 keep-alive connections, the two servers alternating block by block (the order flipped every
other block), so both see the same machine load; CPU is user + system of the server process from
/proc, over its blocks. Two kinds: distinct practical reports (a focus in mm each, what the page asks
per keystroke: no cache hit) and one repeated query (the cache answers: the HTTP stack's own cost).
Prints CPU per request for each tree and kind, their ratio, and the load average. Linux only.
"""

from __future__ import annotations

import argparse
import asyncio
import os
import random
import re
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from serve import REPEATED, Conn, keystroke, server_cpu  # noqa: E402


def start(env: dict):
    proc = subprocess.Popen([sys.executable, "-m", "physcam", "serve", "--port", "0", "--rate-limit", "100000"],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, env={**os.environ, **env})
    m = re.search(r"http://127\.0\.0\.1:(\d+)/", proc.stdout.readline())
    if not m:
        proc.kill()
        raise SystemExit("physcam serve did not start")
    return proc, int(m.group(1))


async def closed_loop(port: int, paths: list[str], connections: int = 4) -> None:
    conns, left = [Conn(port) for _ in range(connections)], iter(paths)

    async def one(c):
        for path in left:
            await c.request(path)

    await asyncio.gather(*(one(c) for c in conns))
    for c in conns:
        await c.close()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", required=True, help="the other tree's src folder (run with PYTHONPATH)")
    ap.add_argument("--blocks", type=int, default=10, help="blocks per tree and kind (default 10)")
    ap.add_argument("--size", type=int, default=400, help="requests per block (default 400)")
    args = ap.parse_args()
    if not (1 <= args.blocks <= 100 and 10 <= args.size <= 5000):
        raise SystemExit("bounded runs only: 1-100 blocks of 10-5000 requests")
    trees = {"baseline": {"PYTHONPATH": str(Path(args.baseline).resolve())}, "this tree": {}}
    servers = {name: start(env) for name, env in trees.items()}
    rng, loads = random.Random(11), []
    cpu = {(t, k): 0.0 for t in trees for k in ("distinct", "repeated")}
    try:
        for proc, port in servers.values():  # warm up: imports, first answers
            asyncio.run(closed_loop(port, [keystroke(rng)[0][1] for _ in range(300)] + [REPEATED] * 50))
        for b in range(args.blocks):
            for kind in ("distinct", "repeated"):
                paths = [keystroke(rng)[0][1] if kind == "distinct" else REPEATED for _ in range(args.size)]
                for name in (list(trees) if b % 2 == 0 else list(trees)[::-1]):
                    proc, port = servers[name]
                    c0 = server_cpu(proc)
                    asyncio.run(closed_loop(port, paths))
                    cpu[name, kind] += server_cpu(proc) - c0
            loads.append(os.getloadavg()[0])
    finally:
        for proc, _ in servers.values():
            proc.terminate()
            proc.wait()
    n = args.blocks * args.size
    for kind in ("distinct", "repeated"):
        base, this = (cpu[t, kind] / n * 1000 for t in trees)
        print(f"{kind}: baseline {base:.3f} ms, this tree {this:.3f} ms of server CPU per request; ratio {this / base:.2f}")
    print(f"load (1 min) {min(loads):.1f}-{max(loads):.1f}; {args.blocks} blocks of {args.size} requests per tree and kind")


if __name__ == "__main__":
    main()
