"""Memory of reading a large camera-metadata CSV: an ARRI Meta Extract file of N real rows.

Goal (issue 40 item 9): reading a metadata CSV takes memory near its size, not a multiple of it (it
took about 16 times: the whole text, its lines, and a dictionary of every row's 183 cells). The
file repeats the real sample's 500 rows with a Master TC counting on (docs/camera-metadata.md);
the measure is tracemalloc's peak of Python allocations during ``physcam.metadata.load``, and the
CPU time of the load (process time; the machine is shared).
    .venv/bin/python benchmarks/metadata_memory.py [--rows 17000] [--json]
"""

import argparse
import json
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

GOAL_RATIO = 1.0
SAMPLE = Path(__file__).resolve().parents[1] / "tests" / "data" / "camera-metadata" / "arri" / \
    "B001C001_180327_R1ZA.mov.csv"


def write_ame(path: Path, rows: int) -> int:
    src = SAMPLE.read_text(encoding="utf-8").splitlines()
    idx = [i for i, h in enumerate(src[0].split("\t")) if h == "Master TC"]
    with path.open("w", encoding="utf-8") as fh:
        fh.write(src[0] + "\n")
        for k in range(rows):
            cells = src[1 + k % 500].split("\t")
            s, f = divmod(1176223 + k, 24)  # the sample's first Master TC Frame Count, at 24 fps
            for i in idx:
                cells[i] = f"{s // 3600:02d}:{s // 60 % 60:02d}:{s % 60:02d}:{f:02d}"
            fh.write("\t".join(cells) + "\n")
    return path.stat().st_size


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rows", type=int, default=17_000)
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    from physcam.metadata import load

    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "big.mov.csv"
        size = write_ame(p, args.rows)
        tracemalloc.start()
        t = time.process_time()
        rec = load(p)
        cpu = time.process_time() - t
        kept, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
    out = {"rows": len(rec.frames), "file_mb": size / 1e6, "peak_mb": peak / 1e6, "kept_mb": kept / 1e6,
           "peak_over_size": peak / size, "cpu_s": cpu, "goal_peak_over_size": GOAL_RATIO}
    if args.json:
        print(json.dumps(out))
    else:
        print(f"{out['rows']} rows, {out['file_mb']:.1f} MB: peak {out['peak_mb']:.1f} MB "
              f"({out['peak_over_size']:.2f} x the file; goal < {GOAL_RATIO:g}), frames kept {out['kept_mb']:.1f} MB, "
              f"{cpu:.2f} s CPU (under tracemalloc)")
    return 0 if out["peak_over_size"] < GOAL_RATIO else 1


if __name__ == "__main__":
    sys.exit(main())
