"""Issue 9.1: a file physcam writes places its camera identically in a plain usd-core process that
has never heard of physcam (no plugin, no PXR_PLUGINPATH_NAME), as Blender's importer or another
studio tool would open it. USD's schema fallback types (``fallbackPrimTypes`` layer metadata)
carry the mechanism; this test checks its effect: the same camera-to-world transform and the same
Gf.Camera frustum for every UsdGeomCamera, with and without the plugin."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from physcam.lens.library import load_lens
from physcam.usd.author import CameraSpec, write_camera
from physcam.usd.kit import write_body_file, write_lens_file, write_previs_kit, write_shot, write_vendor_lens

PROBE = r"""
import json, sys
from pxr import Usd, UsdGeom
out = {}
for f in sys.argv[1:]:
    stage = Usd.Stage.Open(f)
    cams = {}
    for prim in stage.Traverse():
        if prim.IsA(UsdGeom.Camera):
            m = UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(Usd.TimeCode.Default())
            gf = UsdGeom.Camera(prim).GetCamera(Usd.TimeCode.Default())
            fr = gf.frustum
            w = fr.GetWindow()
            cams[str(prim.GetPath())] = {
                "matrix": [m[i][j] for i in range(4) for j in range(4)],
                "window": [w.GetMin()[0], w.GetMin()[1], w.GetMax()[0], w.GetMax()[1]],
                "near_far": [fr.GetNearFar().GetMin(), fr.GetNearFar().GetMax()],
                "position": list(fr.GetPosition()),
                "hfov": gf.GetFieldOfView(gf.FOVHorizontal),
            }
    out[f] = {"types": {str(p.GetPath()): str(p.GetPrimTypeInfo().GetSchemaTypeName()) for p in stage.Traverse()},
              "cameras": cams}
print(json.dumps(out))
"""


def probe(files, plugin: bool):
    env = {k: v for k, v in os.environ.items() if k != "PXR_PLUGINPATH_NAME"}
    if plugin:
        from physcam.usd.plugin import PLUGIN_DIR

        env["PXR_PLUGINPATH_NAME"] = str(PLUGIN_DIR)
    p = subprocess.run([sys.executable, "-c", PROBE, *map(str, files)], capture_output=True, text=True, env=env)
    assert p.returncode == 0, p.stderr
    return json.loads(p.stdout)


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    d = tmp_path_factory.mktemp("noplugin")
    files = [
        write_camera(d / "cam.usda", CameraSpec.of(focal_length_mm=35.0, fstop=2.8, focus_mm=2500.0, shift_mm=(1.0, -2.0)),
                     position=(120.0, 150.0, -40.0), rotate_xyz_deg=(-5.0, 30.0, 2.0)),
        write_camera(d / "ortho.usda", CameraSpec.of(projection="orthographic", magnification=0.5),
                     position=(0.0, 10.0, 0.0), rotate_xyz_deg=(-90.0, 0.0, 0.0)),
        write_camera(d / "crate.usdc", CameraSpec.of(focal_length_mm=85.0), position=(1.0, 2.0, 3.0)),
        write_previs_kit(d / "kit.usda"),
        write_vendor_lens(d / "vendor.usda", load_lens("dgauss_50mm"), focus_mm=1500.0, fstop=4.0),
    ]
    from physcam.optics.sensors import find_sensor
    from physcam.usd.animate import FocusKey, write_animated_camera

    files.append(write_animated_camera(d / "pull.usda", [FocusKey(1, 5000.0), FocusKey(2, 3000.0), FocusKey(3, 1000.0)],
                                       sensor=find_sensor("FF"), lens=load_lens("dgauss_50mm"), fstop=2.8,
                                       position=(10.0, 160.0, 300.0), rotate_xyz_deg=(0.0, -20.0, 0.0)))
    body = write_body_file(d / "body.usda", CameraSpec.of(sensor_width_mm=27.99, sensor_height_mm=19.22))
    lens = write_lens_file(d / "lens.usda", {"2026-03-01": CameraSpec.of(focal_length_mm=24.0, entrance_pupil_mm=80.0)})
    files += [body, lens, write_shot(d / "shot.usda", body, lens, position=(300.0, 170.0, 500.0),
                                     rotate_xyz_deg=(0.0, -45.0, 0.0)),
              write_shot(d / "vendor_shot.usda", body, files[4], position=(-20.0, 90.0, 40.0),
                         rotate_xyz_deg=(10.0, 20.0, 0.0))]
    return files


def test_camera_placement_is_the_same_without_the_plugin(written):
    with_plugin = probe(written, plugin=True)
    without = probe(written, plugin=False)
    n = 0
    for f in map(str, written):
        a, b = with_plugin[f]["cameras"], without[f]["cameras"]
        assert a.keys() == b.keys(), f
        for path in a:
            n += 1
            for key in ("matrix", "window", "near_far", "position"):
                assert b[path][key] == pytest.approx(a[path][key], rel=1e-9, abs=1e-9), f"{f} {path} {key}"
            assert b[path]["hfov"] == pytest.approx(a[path]["hfov"], rel=1e-9)
        # without the plugin the PhysicalCamera prims take their fallback type, one plain USD knows
        assert "PhysicalCamera" not in without[f]["types"].values() or not a, f
    assert n >= 7  # camera, orthographic, crate, kit, focus pull, two shots (body, lens, vendor files hold none)


def test_placed_camera_is_not_at_the_origin_without_the_plugin(written):
    """The regression the issue reports: the companion camera landed at the origin. Its eye is the
    entrance pupil, which the body was placed at (120, 150, -40) cm."""
    cam = probe([written[0]], plugin=False)[str(written[0])]["cameras"]["/Cameras/Camera/Camera"]
    assert cam["position"] == pytest.approx([120.0, 150.0, -40.0], abs=1e-9)
