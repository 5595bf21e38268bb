"""The Blender extension's iris levels per bundled lens: where the area's cubic in iris radius misses (round 10:
at any film radius up to RADIAL_MAX_MM) and only inside the lens's image circle (round 11, blender_pupil._in_circle).

Run:  .venv/bin/python benchmarks/blender_levels.py [--lenses dgauss_50mm,...]

For every bundled prime with rotational symmetry (zooms keep iris_levels' 26 in blender_zoom; anamorphic lenses
have no radial table) :func:`physcam.export.blender_focus.focus_table` is built once; its traced marks' tables
and checks (the arguments of ``_refined_levels``) are kept, and the levels are counted again with every film
radius counted (``_in_circle`` taken as everywhere): both rules on the same traced sets. Prints per lens the
levels of both rules, the image circle the rule used (the first film radius, mm, where the chief ray is cut at
some traced focus: nothing passes at the smallest iris) and the CPU seconds of ``focus_table``. About 3 min.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

import physcam.export.blender_pupil as bp
from physcam.export.blender_focus import focus_table
from physcam.lens.library import list_lenses, load_lens


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lenses", help="comma-separated lens names (default: every bundled prime)")
    args = ap.parse_args()
    names = args.lenses.split(",") if args.lenses else [r.slug for r in list_lenses()]
    kept, rule = {}, bp._refined_levels

    def keeping(levels, tables, checks):
        kept["args"] = (np.array(levels), [np.array(t) for t in tables], [np.array(c) for c in checks])
        return rule(levels, tables, checks)

    bp._refined_levels = keeping
    everywhere = lambda rhos, lit: np.ones(np.asarray(rhos).size, dtype=bool)  # noqa: E731
    print(f"{'lens':44s} {'every radius':>12s} {'in circle':>9s} {'circle mm':>9s} {'CPU s':>6s}")
    totals = [0, 0]
    for name in names:
        lens = load_lens(name)
        if lens.is_anamorphic or lens.zoom is not None:
            continue
        kept.clear()
        t0 = time.process_time()
        ft = focus_table(lens)
        cpu = time.process_time() - t0
        levels, tables, checks = kept["args"]
        circle = bp._in_circle
        bp._in_circle = everywhere
        try:
            n_all = len(rule(levels, tables, checks))
        finally:
            bp._in_circle = circle
        rhos, checked = bp._check_axes(levels)
        lit = np.all([np.reshape(c, (rhos.size, checked.size))[:, -1] > 0 for c in checks], axis=0)
        edge = float(rhos[~lit].min()) if not lit.all() else math.inf
        totals[0] += n_all
        totals[1] += len(ft.iris_radii)
        print(f"{name:44s} {n_all:12d} {len(ft.iris_radii):9d} {edge:9.1f} {cpu:6.1f}", flush=True)
    print(f"{'total':44s} {totals[0]:12d} {totals[1]:9d}")


if __name__ == "__main__":
    main()
