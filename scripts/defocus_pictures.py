"""docs/img/defocus_*.png: the pictures of docs/defocus.md, before and after issue 42.

Run the Cycles proofs keeping their renders, then this script on their folders:

    python -m pytest -q -m slow tests/blender/test_defocus_cycles.py --basetemp=/tmp/dfc -p no:cacheprovider
    python -m pytest -q -m slow tests/blender/test_defocus_cycles_anamorphic.py --basetemp=/tmp/dfa -p no:cacheprovider
    python scripts/defocus_pictures.py /tmp/dfc/defocus_cycles0 /tmp/dfa/defocus_anamorphic0 [--before CHECKOUT]

``--before CHECKOUT``: a checkout of physcam before issue 42 (e.g. a worktree at d947395): its
``physcam defocus`` of the same inputs is run in a fresh process (``CHECKOUT/src`` first on the
path) and shown beside this one's.

Panels (linear light shown with the sRGB curve): the Cycles scene (the truth through physcam's OSL
real-lens camera; physcam defocus of the pinhole render, redistorted by physcam's ST map; before;
Cycles' own thin-lens depth of field); the spheres enlarged; two scenes of issue 42 (a flat
in-focus checker divided by the relative illumination, where tile steps show; a small bright spot
beside a near surface); the anamorphic oval bokeh.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from physcam.analysis.defocus.render import defocus, inverse_depth
from physcam.analysis.defocus.exr import read_exr
from physcam.analysis.defocus.kernels import KernelCache, defocus_camera
from physcam.analysis.distortion.stmap import apply_stmap, distortion_field
from physcam.lens.library import load_lens
from physcam.optics.state import camera_state
from physcam.trace.aperture import Aperture

OUT = Path(__file__).resolve().parents[1] / "docs" / "img"
W, H, SW = 320, 180, 36.0

#: run in the "before" checkout: defocus each (image.npy, depth.npy, width, height, tile, blades, out.npy)
_BEFORE = """
import json, sys
import numpy as np
from physcam.analysis.defocus.render import defocus, inverse_depth
from physcam.analysis.defocus.kernels import KernelCache, defocus_camera
from physcam.lens.library import load_lens
from physcam.trace.aperture import Aperture
for img, z, w, h, tile, blades, out in json.loads(sys.argv[1]):
    cam = defocus_camera(load_lens("dgauss_50mm"), focus_mm=2000.0, fstop=2.8, sensor_width_mm=36.0, width=w, height=h,
                         aperture=Aperture(blades, 15.0) if blades else None, tile=tile)
    np.save(out, defocus(np.load(img), inverse_depth(np.load(z), cam), KernelCache(cam)))
"""


def _rgb(path):
    e = read_exr(path)
    return np.stack([e.channels[c] for c in "RGB"], axis=2)


def _srgb(x, white):
    x = np.clip(x / white, 0, 1)
    return (255 * np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055) + 0.5).astype(np.uint8)


def _strip(panels, labels, path, white, scale=1.0):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    h, w = panels[0].shape[:2]
    fig, axes = plt.subplots(1, len(panels), figsize=(len(panels) * w * scale / 100, h * scale / 100 + 0.35), dpi=100)
    for ax, img, label in zip(np.atleast_1d(axes), panels, labels):
        ax.imshow(_srgb(img, white) if img.ndim == 3 else img, interpolation="nearest",
                  **({} if img.ndim == 3 else {"cmap": "RdBu_r", "vmin": 0.85, "vmax": 1.15}))
        ax.set_title(label, fontsize=8)
        ax.axis("off")
    fig.tight_layout(pad=0.2)
    fig.savefig(path)
    plt.close(fig)
    print(f"wrote {path}")


def _before(jobs, checkout):
    """The old defocus of ``jobs`` [(image, depth m, width, height, tile, blades)], run in ``checkout``."""
    if checkout is None:
        return [None] * len(jobs)
    import os

    with tempfile.TemporaryDirectory() as tmp:
        args = []
        for i, (img, z, w, h, tile, blades) in enumerate(jobs):
            np.save(f"{tmp}/i{i}.npy", img)
            np.save(f"{tmp}/z{i}.npy", z)
            args.append([f"{tmp}/i{i}.npy", f"{tmp}/z{i}.npy", w, h, tile, blades, f"{tmp}/o{i}.npy"])
        env = dict(os.environ, PYTHONPATH=str(Path(checkout) / "src"))
        subprocess.run([sys.executable, "-c", _BEFORE, json.dumps(args)], check=True, env=env)
        return [np.load(a[-1]) for a in args]


def _dgauss_at_2m(w, h):
    """dgauss_50mm at 2 m, f/2.8, on a 36 mm wide sensor of the frame's aspect (the defocus reads its width)."""
    return camera_state(load_lens("dgauss_50mm"), focus_mm=2000.0, fstop=2.8, sensor_mm=(36.0, 36.0 * h / w))


def _issue_scenes():
    """(name, image, depth m, width, height, tile): the in-focus checker and the spot beside a surface."""
    w, h = 256, 144
    cam = defocus_camera(_dgauss_at_2m(w, h), width=w, height=h)
    ys, xs = np.indices((h, w))
    check = np.where(((xs // 8) + (ys // 8)) % 2, 1.0, 0.5).astype(np.float32)[..., None].repeat(3, axis=2)
    focus = np.full((h, w), (cam.focus_mm - cam.pupil_from_film_mm) / 1000)
    spot = np.zeros((h, w, 3), np.float32)
    spot[70:74, 130:134] = 40.0
    z = np.full((h, w), 1e10)
    z[:, :130] = 0.45
    z[70:74, 130:134] = 0.5
    return [("checker", check, focus, w, h, 64), ("spot", spot, z, w, h, 64)]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("spherical")
    ap.add_argument("anamorphic", nargs="?")
    ap.add_argument("--before", default=None, help="a checkout of physcam before issue 42")
    a = ap.parse_args()
    d = Path(a.spherical)
    lens = load_lens("dgauss_50mm")
    state = camera_state(lens, focus_mm=2000.0, fstop=2.8, sensor_mm=(SW, SW * H / W))
    cam = defocus_camera(state, width=W, height=H, aperture=Aperture(6, 15.0), tile=32)
    dist = distortion_field(state, width_px=W, height_px=H)
    cache = KernelCache(cam)
    jobs, imgs = [], {}
    for tag in ("", "_spheres"):
        z = read_exr(d / f"depth{tag}.exr").channels["R"]
        pin = _rgb(d / f"pinhole{tag}.exr")
        imgs[tag] = [_rgb(d / f"truth{tag}.exr"),
                     apply_stmap(defocus(pin, inverse_depth(z, cam), cache), dist.distortion_stmap),
                     _rgb(d / f"cycles_dof{tag}.exr")]
        jobs.append((pin, z, W, H, 32, 6))
    scenes = _issue_scenes()
    jobs += [(img, z, w, h, tile, 0) for _, img, z, w, h, tile in scenes]
    before = _before(jobs, a.before)
    labels = ["truth: Cycles through physcam's OSL lens", "physcam defocus (now)", "Cycles thin-lens DOF"]
    if before[0] is not None:
        for k, tag in enumerate(("", "_spheres")):
            imgs[tag].insert(2, apply_stmap(before[k], dist.distortion_stmap))
        labels.insert(2, "physcam defocus (before)")
    _strip(imgs[""], labels, OUT / "defocus_scene.png", white=1.0)
    crops = []
    for x, y in ((160, 90), (304, 16)):
        crops.append([np.kron(i[max(y - 16, 0): y + 16, x - 16: x + 16], np.ones((4, 4, 1))) for i in imgs["_spheres"]])
    _strip([np.concatenate([p, q], axis=0) for p, q in zip(*crops)], [s.split(":")[0] for s in labels],
           OUT / "defocus_bokeh.png", white=3.0)
    _issue_pictures(scenes, before[2:])
    if a.anamorphic:
        _anamorphic(Path(a.anamorphic))


def _issue_pictures(scenes, before):
    """Before and after on the two scenes of issue 42."""
    panels, labels = [], []
    for (name, img, z, w, h, tile), old in zip(scenes, before):
        cam = defocus_camera(_dgauss_at_2m(w, h), width=w, height=h, tile=tile)
        cache = KernelCache(cam)
        new = defocus(img, inverse_depth(z, cam), cache)
        if name == "checker":  # divided by the plate and T: 1 everywhere when light is kept and nothing steps
            ys, xs = np.mgrid[0:h, 0:w] + 0.5
            t = cache.transmission(xs, ys, 0)[..., 0]
            panels += [new[..., 1] / img[..., 1] / t] + ([old[..., 1] / img[..., 1] / t] if old is not None else [])
            labels += ["in-focus checker / (plate x T), now"] + (["before (tile steps)"] if old is not None else [])
        else:
            panels += [new] + ([old] if old is not None else [])
            labels += ["spot beside a near surface, now"] + (["before (bars)"] if old is not None else [])
    for k, (p, lab) in enumerate(zip(panels, labels)):
        if p.ndim == 3:
            panels[k] = np.clip(p / 0.5, 0, None)
    _strip(panels, labels, OUT / "defocus_issue.png", white=1.0, scale=1.5)


def _anamorphic(d: Path):
    """The anamorphic oval bokeh: truth and physcam, enlarged, both squeezed (the film image)."""
    lens = load_lens("neil_front_anamorphic_2x")
    w, h = 384, 288
    state = camera_state(lens, focus_mm=2000.0, fstop=2.8, sensor_mm=(20.0, 15.0))
    cam = defocus_camera(state, width=w, height=h, tile=32)
    dist = distortion_field(state, width_px=w, height_px=h)
    u = inverse_depth(read_exr(d / "depth_spheres.exr").channels["R"], cam)
    phys = apply_stmap(defocus(_rgb(d / "pinhole_spheres.exr"), u, KernelCache(cam)), dist.distortion_stmap)
    truth = _rgb(d / "truth_spheres.exr")
    y, x = np.unravel_index(np.argmax(truth[..., 1]), truth.shape[:2])
    crops = [np.kron(i[max(y - 24, 0): y + 24, max(x - 24, 0): x + 24], np.ones((3, 3, 1))) for i in (truth, phys)]
    _strip(crops, ["truth (OSL), film image", "physcam defocus"], OUT / "defocus_anamorphic.png",
           white=float(np.percentile(truth, 99.9)))


if __name__ == "__main__":
    main()
