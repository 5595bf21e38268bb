"""Memory of an 8K ST-map: dgauss.50mm on a Super 35 gate at 8192 x 4320, both maps built and written.

Goal (issue 24 item 12): a peak resident memory under 2 GiB (it was 2.3 GB). The maps are built and
encoded in blocks of rows and each file is written before the next is encoded (docs/performance.md).
Each run is a fresh process (its peak resident memory, ru_maxrss, is the measure), so a number
here is not raised by what an earlier run left allocated.
    .venv/bin/python benchmarks/stmap_memory.py [--width 8192 --height 4320] [--json]
"""

import argparse
import json
import subprocess
import sys

GOAL_MIB = 2048

#: the child: build the maps, write them, report the peak resident memory before and after
CHILD = r"""
import json, resource, sys, tempfile, time
from physcam.analysis.distortion.stmap import distortion_field, write_stmaps
from physcam.lens.library import load_lens

w, h = int(sys.argv[1]), int(sys.argv[2])
lens = load_lens("dgauss_50mm")
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
t = time.perf_counter()
res = distortion_field(lens, focus_mm=3000.0, sensor_width_mm=24.89, sensor_height_mm=24.89 * h / w,
                       width_px=w, height_px=h)
built = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
with tempfile.TemporaryDirectory() as d:
    paths = write_stmaps(res, d)
    sizes = {p.name: p.stat().st_size for p in paths}
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps({"width": w, "height": h, "seconds": time.perf_counter() - t, "before_mib": before,
                  "built_mib": built, "peak_mib": peak, "files": sizes}))
"""


def measure(width: int, height: int) -> dict:
    """Build and write the maps in a fresh process; its measurements."""
    out = subprocess.run([sys.executable, "-c", CHILD, str(width), str(height)], capture_output=True, text=True,
                         check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--width", type=int, default=8192)
    ap.add_argument("--height", type=int, default=4320)
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    r = measure(args.width, args.height)
    if args.json:
        print(json.dumps(r))
        return
    print(f"ST-maps {r['width']} x {r['height']}: built and written in {r['seconds']:.1f} s")
    print(f"peak resident memory {r['peak_mib']:.0f} MiB (after building {r['built_mib']:.0f} MiB, at start "
          f"{r['before_mib']:.0f} MiB); goal {GOAL_MIB} MiB: ratio {r['peak_mib'] / GOAL_MIB:.2f} "
          f"({'met' if r['peak_mib'] < GOAL_MIB else 'NOT met'})")


if __name__ == "__main__":
    main()
