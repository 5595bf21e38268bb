"""USD file names in any case (round 22): one rule, ``physcam.usd_names.usd_layer_format``, for every writer and
command line. USD itself tells a layer's format by its extension in any case; checked here against usd-core:
what physcam writes under each name is what USD reads back, in the format the name asks for."""

from __future__ import annotations

import pytest

from physcam.errors import ExportError
from physcam.usd_names import usd_layer_format


@pytest.mark.parametrize("name, fmt", [("shot.usda", "usda"), ("SHOT.USDA", "usda"), ("a.b.Usda", "usda"),
                                        ("shot.usd", "usdc"), ("SHOT.USD", "usdc"), ("shot.usdc", "usdc"),
                                        ("x/SHOT.UsdC", "usdc")])
def test_the_format_is_the_extensions_in_any_case(name, fmt):
    assert usd_layer_format(name) == fmt


@pytest.mark.parametrize("name", ["shot", "shot.txt", "shot.usdz", "shot.usda.bak", "usda"])
def test_other_names_are_refused_naming_the_file(name):
    with pytest.raises(ExportError, match=rf"^{name}: a USD file's name ends in \.usda, \.usd or \.usdc$"):
        usd_layer_format(name)


@pytest.mark.parametrize("name, magic", [("SHOT.USDA", b"#usda 1.0"), ("Shot.Usd", b"PXR-USDC"),
                                         ("shot.USDC", b"PXR-USDC")])
def test_save_stage_writes_what_the_name_asks_and_usd_reads_it(tmp_path, name, magic):
    pytest.importorskip("pxr")
    from pxr import Usd

    from physcam.usd.author import CameraSpec, author_camera, new_stage, save_stage

    stage = new_stage()
    author_camera(stage, "/Cameras/Camera", CameraSpec.of(focal_length_mm=35.0, fstop=2.8, focus_mm=3000.0))
    path = save_stage(stage, tmp_path / name)
    assert path.read_bytes().startswith(magic)
    assert Usd.Stage.Open(str(path)).GetPrimAtPath("/Cameras/Camera").GetTypeName() == "PhysicalCamera"
    assert sorted(p.name for p in tmp_path.iterdir()) == [name]
