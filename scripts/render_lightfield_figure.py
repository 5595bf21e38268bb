"""Render docs/img/microlens_planes.png: the raw light field behind a microlens array, sub-aperture
views and refocused pictures of two checkerboards at different depths (docs/microlens.md).

    PYTHONPATH=src python scripts/render_lightfield_figure.py [--force]
"""

import sys
from pathlib import Path

import numpy as np

from physcam.analysis.defocus.lightfield import checkerboard, light_field_figure, render_planes, view_disparity
from physcam.lens.library import load_lens
from physcam.trace.microlens import microlens_array, plenoptic_camera

OUT = Path(__file__).resolve().parents[1] / "docs" / "img" / "microlens_planes.png"


def main(force: bool = False) -> None:
    # dgauss.50mm at f/5.6 focused 1 m from the sensor; 101 x 101 thin lenslets, 40 um, f/5.6
    array = microlens_array(101, 101, 4.04, 4.04, focal_length_mm=0.224)
    cam = plenoptic_camera(load_lens("dgauss_50mm"), array, focus_mm=1000.0, fstop=5.6, pixels_per_lenslet=9)
    near = checkerboard(4, 16)
    far = 1.0 - checkerboard(10, 8)
    far[:8, :8] = 0.25
    field = render_planes(cam, [(far, 3000.0, 260.0), (near, 600.0, 24.0, (-8.0, 4.0))], spp=6, seed=1)
    slopes = [(f"refocused at {d / 1000:g} m", view_disparity(cam, d)) for d in (600.0, 1000.0, 3000.0)]
    path = light_field_figure(field, views_shown=3, refocus_slopes=slopes, path=OUT, force=force)
    print(f"wrote {path}; slopes {[round(s, 3) for _, s in slopes]}; total {float(np.sum(field.raw)):.4g}")


if __name__ == "__main__":
    main(force="--force" in sys.argv)
