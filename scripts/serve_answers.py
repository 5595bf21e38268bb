"""Print every answer of ``physcam serve``'s report endpoints for N random queries, one JSON line each
(status, headers, body), from the ASGI app in this process: run it in two trees and compare the files,
to show a change to the server or the report answers byte for byte as before (issue 47).

    PYTHONPATH=/path/to/other/tree/src python scripts/serve_answers.py 400 1 > before.jsonl
    python scripts/serve_answers.py 400 1 > after.jsonl
    cmp before.jsonl after.jsonl

The queries are the page's (practical setups, a focus typed in mm as per keystroke, feet, CoC names and
values, squeeze, T-stop, measured near/far limits, the technical model's planes, bundled lenses, focus
tables) with a share of values the server refuses, so refusals are compared too. What the HTTP layer
adds (uvicorn's date, connection headers) is not in it.
"""

from __future__ import annotations

import asyncio
import json
import random
import sys
import warnings
from urllib.parse import urlencode

from physcam.cli.serve import cli_backend
from physcam.errors import PhysCamWarning
from physcam.serve import Limits, create_app

#: Values per query name; the first ones of each list are ones the page sends, the last ones are refused.
CHOICES = {
    "focal": ["18", "24", "35", "50", "85.5", "135", "0", "-5", "abc", "1e400", "50mm", "2in", "nan"],
    "fstop": ["1.4", "2", "2.8", "4", "5.6", "8", "11", "22", "0", "x", "0.5"],
    "tstop": ["1.5", "2.1", "2.9", "4.2", "3"],
    "focus": ["600mm", "1m", "2.5m", "3000", "10ft", "10'6\"", "hyperfocal", "infinity", "inf", "30m", "0.1m", "1e9",
              "12", "-2m", "5 ft", "3M", "1.2m"],
    "sensor": ["S35", "ALEXA 35", "FF", "VENICE 2", "Super 16", "ALEXA Mini LF", "anamorphic-35", "nope", "16mm"],
    "sensor-width": ["24.89", "36", "0", "-1", "8.8"],
    "sensor-height": ["18.66", "24", "13.5"],
    "squeeze": ["1", "1.33", "2", "1.8", "0"],
    "coc": ["0.025", "d/1500", "d/1000", "cine", "25um", "0.03mm", "full-frame", "bogus", "d/1730"],
    "near": ["2m", "1.5m", "8ft", "2500", "100m"],
    "far": ["4m", "inf", "14ft", "3500", "1m"],
    "model": ["practical", "technical", "other"],
    "h1": ["62", "46.24", "10"], "h2": ["51.3", "51.69", "40"], "pupil": ["92", "49.53", "60"],
    "reference": ["film", "flange"], "flange": ["52", "44"],
    "sensor-front": ["150", "200mm", "6in"], "lens-length": ["100", "80mm"], "pupil-fraction": ["0.4", "0.5", "1.5"],
    "meters-per-unit": ["0.01", "1", "0.1"], "shutter-angle": ["180", "172.8", "360", "45"],
    "shift-x": ["0", "2", "-1.5"], "shift-y": ["0", "1", "-2"], "units": ["m", "ft"],
}
LENSES = ["dgauss_50mm", "zuiko_18mm_f3_5", "dgauss.50mm", "nope_lens", "fisheye_10mm"]
RARE = ("sensor-width", "sensor-height", "sensor-front", "lens-length", "pupil-fraction", "h1", "h2", "pupil", "flange",
        "model")


def query(rng: random.Random) -> dict:
    """One random query of the report endpoint."""
    q = {}
    if rng.random() < 0.12:
        q["lens"] = rng.choice(LENSES)
    elif rng.random() < 0.97:
        q["focal"] = rng.choice(CHOICES["focal"][:6] * 3 + CHOICES["focal"])
    for k in ("fstop", "focus", "sensor"):
        if rng.random() < 0.85:
            q[k] = rng.choice(CHOICES[k])
    if rng.random() < 0.5:  # a focus typed in mm, as the page sends it per keystroke
        q["focus"] = f"{rng.uniform(300, 40000):.0f}mm"
    if rng.random() < 0.8:  # mostly answers
        q["fstop"], q["sensor"] = rng.choice(CHOICES["fstop"][:8]), rng.choice(CHOICES["sensor"][:7])
    extra = [k for k in CHOICES if k not in ("focal", "fstop", "focus", "sensor") and (rng.random() < 0.3 or k not in RARE)]
    for k in rng.sample(extra, rng.choice([0, 0, 1, 2, 3, 4])):
        q[k] = rng.choice(CHOICES[k])
    if q.get("model") == "technical" and rng.random() < 0.7:
        q.update(h1=rng.choice(CHOICES["h1"]), h2=rng.choice(CHOICES["h2"]), pupil=rng.choice(CHOICES["pupil"]))
    if rng.random() < 0.03:
        q["bogus"] = "1"
    if "focal" in q and rng.random() < 0.8:
        q["focal"] = rng.choice(CHOICES["focal"][:6])
    return q


async def answer(app, path: str) -> dict:
    """The app's answer to GET ``path``: status, headers and body."""
    p, _, qs = path.partition("?")
    scope = {"type": "http", "asgi": {"version": "3.0"}, "http_version": "1.1", "method": "GET", "scheme": "http",
             "path": p, "raw_path": p.encode(), "query_string": qs.encode(), "root_path": "",
             "headers": [(b"host", b"localhost")], "client": ("127.0.0.1", 0), "server": ("127.0.0.1", 0)}
    sent = []

    async def receive():
        return {"type": "http.request", "body": b"", "more_body": False}

    async def send(message):
        sent.append(message)

    await app(scope, receive, send)
    return {"path": path, "status": sent[0]["status"],
            "headers": [[k.decode(), v.decode()] for k, v in sent[0]["headers"]],
            "body": b"".join(m.get("body", b"") for m in sent[1:]).decode()}


async def main(n: int, seed: int) -> None:
    warnings.simplefilter("ignore", PhysCamWarning)
    app = create_app(cli_backend(), Limits(rate=100000, burst=200000))
    rng = random.Random(seed)
    for _ in range(n):
        q = query(rng)
        if rng.random() < 0.08:
            q.pop("focus", None)
            path = "/api/focus-table?" + urlencode({**q, "marks": rng.choice(["1m,2m,3m", "10ft,20mm", "2m"])})
        else:
            path = "/api/report?" + urlencode(q)
        print(json.dumps(await answer(app, path), ensure_ascii=False))


if __name__ == "__main__":
    asyncio.run(main(int(sys.argv[1]) if len(sys.argv) > 1 else 400, int(sys.argv[2]) if len(sys.argv) > 2 else 1))
