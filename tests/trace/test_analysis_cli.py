"""Spot diagram, bokeh image and their CLI commands."""

import json

import numpy as np
import pytest

from physcam.analysis.defocus.bokeh import bokeh_image
from physcam.analysis.image_quality.spot import spot_diagram
from physcam.cli import main
from physcam.errors import InputError


def test_spot_diagram_reproduces_the_published_on_axis_rms(dgauss):
    # issue 5 acceptance figure: 6.7099 um for a beam of 11 mm radius at the paraxial image plane (d line)
    res = spot_diagram(dgauss, (0.0,), pupil_radius=11.0, rings=300)
    f = res.fields[0]
    assert f.rays_passed == f.rays_launched
    assert f.rms_radius_um == pytest.approx(6.7099, abs=0.001)
    assert f.geometric_radius_um >= f.rms_radius_um


def test_bokeh_on_axis_is_centred_and_conserves_weight(dgauss):
    res = bokeh_image(dgauss, 800.0, rays=60_000, pixels=64, chunk=20_000, fresnel=False)
    cx, cy = res.to_dict()["centroid_mm"]
    assert abs(cx) < 0.01 and abs(cy) < 0.01
    assert res.image.sum() > 0 and np.isfinite(res.image).all()
    with pytest.raises(InputError):
        bokeh_image(dgauss, 10.0)  # the light would sit behind the front vertex


def test_cli_spot_and_bokeh(tmp_path, capsys):
    png = tmp_path / "spot.png"
    assert main(["spot", "dgauss.50mm", "--field", "0", "--rings", "10", "--json", "-o", str(png)]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["fields"][0]["rays_passed"] > 0 and png.stat().st_size > 1000
    assert main(["spot", "dgauss.50mm", "--rings", "10", "-o", str(png)]) == 2  # exists, no --force
    assert "--force" in capsys.readouterr().err
    assert main(["bokeh", "dgauss.50mm", "--depth", "1m", "--rays", "20000", "--pixels", "32", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["rays_passed"] > 0


def test_stopping_down_shrinks_the_axial_spot():
    # on axis, at the paraxial focus, spherical aberration grows with the aperture: every stop
    # down shrinks the RMS spot, and every ray that passes lies within the stopped pupil
    from physcam.analysis.image_quality.spot import spot_diagram
    from physcam.lens.library import load_lens
    from physcam.optics.state import as_designed

    lens = load_lens("dgauss_50mm")
    rms = [spot_diagram(as_designed(lens, fstop=n), (0.0,), rings=20).fields[0].rms_radius_um
           for n in (2.1, 2.8, 4.0, 5.6, 8.0)]
    assert all(a > b for a, b in zip(rms, rms[1:]))
