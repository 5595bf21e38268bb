"""docs/img/defocus_*.png: the side-by-side pictures of docs/defocus.md from the Cycles proof's renders.

Run the proof keeping its renders, then this script on their folder:

    python -m pytest -q -m slow tests/blender/test_defocus_cycles.py --basetemp=/tmp/dfc -p no:cacheprovider
    python scripts/defocus_pictures.py /tmp/dfc/defocus_cycles0

Panels: the truth (Cycles through physcam's OSL real-lens camera), physcam defocus of the pinhole
render, Blender's compositor Defocus node of the same render; the full scene and, enlarged 4x, the
spheres alone at the centre and the top-right corner. Linear light shown with the sRGB curve.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from physcam.analysis.defocus.render import defocus, inverse_depth
from physcam.analysis.defocus.exr import read_exr
from physcam.analysis.defocus.kernels import KernelCache, defocus_camera
from physcam.lens.library import load_lens
from physcam.trace.aperture import Aperture

OUT = Path(__file__).resolve().parents[1] / "docs" / "img"


def _rgb(path):
    e = read_exr(path)
    return np.stack([e.channels[c] for c in "RGB"], axis=2)


def _srgb(x, white):
    x = np.clip(x / white, 0, 1)
    return (255 * np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055) + 0.5).astype(np.uint8)


def _strip(panels, labels, path, white):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    h, w = panels[0].shape[:2]
    fig, axes = plt.subplots(1, len(panels), figsize=(len(panels) * w / 100, h / 100 + 0.3), dpi=100)
    for ax, img, label in zip(axes, panels, labels):
        ax.imshow(_srgb(img, white), interpolation="nearest")
        ax.set_title(label, fontsize=8)
        ax.axis("off")
    fig.tight_layout(pad=0.2)
    fig.savefig(path)
    plt.close(fig)


def main(folder):
    d = Path(folder)
    cam = defocus_camera(load_lens("dgauss_50mm"), focus_mm=2000.0, fstop=2.8, sensor_width_mm=36.0, width=320,
                         height=180, aperture=Aperture(6, 15.0), tile=32)
    cache = KernelCache(cam)
    labels = ["truth: Cycles, physcam's OSL lens", "physcam defocus of the pinhole", "Blender Defocus node"]
    imgs = {}
    for tag in ("", "_spheres"):
        u = inverse_depth(read_exr(d / f"depth{tag}.exr").channels["R"], cam)
        imgs[tag] = [_rgb(d / f"truth{tag}.exr"), defocus(_rgb(d / f"pinhole{tag}.exr"), u, cache),
                     _rgb(d / f"blender{tag}.exr")]
    _strip(imgs[""], labels, OUT / "defocus_scene.png", white=1.0)
    crops = []
    for x, y in ((160, 90), (304, 16)):
        crops.append([np.kron(i[max(y - 16, 0): y + 16, x - 16: x + 16], np.ones((4, 4, 1))) for i in imgs["_spheres"]])
    _strip([np.concatenate([a, b], axis=0) for a, b in zip(*crops)], ["truth (OSL)", "physcam defocus", "Blender Defocus"],
           OUT / "defocus_bokeh.png", white=3.0)
    print(f"wrote {OUT / 'defocus_scene.png'} and {OUT / 'defocus_bokeh.png'}")


if __name__ == "__main__":
    main(sys.argv[1])
