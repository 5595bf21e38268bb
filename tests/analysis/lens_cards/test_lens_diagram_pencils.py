"""Every ray the lens diagram draws for the default field reaches the film (a first-day review saw
stray light-blue stubs at the lower left: rim rays aimed at the paraxial pupil's edge of a vignetted
field, stopped outside the front element's clear aperture)."""

import matplotlib.colors as mcolors
import pytest

from physcam.analysis.lens_cards.diagram import lens_diagram
from physcam.figures import PALETTE
from physcam.lens.library import load_lens
from physcam.optics.state import camera_state


@pytest.mark.parametrize("name", ["dgauss_50mm", "cooke_triplet_50mm_f4_5", "fisheye_10mm"])
def test_every_drawn_ray_line_ends_on_the_film(name):
    d = lens_diagram(camera_state(load_lens(name)))
    fig = d.figure()
    ray_colours = {mcolors.to_hex(PALETTE[i]) for i in (1, 2, 5)}  # marginal, chief, rim
    rays = [ln for ln in fig.axes[0].lines if mcolors.to_hex(ln.get_color()) in ray_colours
            and len(ln.get_xdata()) > 2]
    assert len(rays) == 6  # three marginal rays, the chief ray and two rim rays
    for ln in rays:  # the matplotlib artist itself: its last point on the film plane
        assert ln.get_xdata()[-1] == pytest.approx(d.gaussian.z_film, abs=1e-6)
    rims = [pts for kind, pts in d.rays if kind == "rim"]
    assert len(rims) == 2 and rims[0][0][1] > rims[1][0][1]  # the upper rim first, then the lower


def test_diagram_prints_where_it_wrote(tmp_path, capsys):
    from physcam.cli import main

    out = tmp_path / "d.png"
    assert main(["lens", "diagram", "--lens", "cooke_triplet_50mm_f4_5", "-o", str(out)]) == 0
    assert out.stat().st_size > 0 and capsys.readouterr().out.strip() == f"wrote {out}"


@pytest.mark.parametrize("name, field_deg", [("dgauss_50mm", 18.0), ("cooke_triplet_50mm_f4_5", 0.0)])
def test_pencil_edges_are_where_a_fine_scan_of_the_pupil_finds_them(name, field_deg):
    """The bisected rim of a pencil (both ends in one batch per step, issue 47) against an independent
    scan: 40,001 rays across the pupil in one trace, the outermost of the run through h = 0 that pass."""
    import math

    import numpy as np

    from physcam.analysis.lens_cards import diagram as D
    from physcam.optics import focusing, paraxial
    from physcam.trace import OK, RayBatch, trace_through

    lens = load_lens(name)
    wl = float(lens.wavelength_nm)
    p = focusing.focus(lens, math.inf, axis="y", wavelength_nm=wl).prescription
    g = paraxial.gaussian(p, axis="y", wavelength_nm=wl)
    a, tu = g.entrance_pupil_diameter / 2, math.tan(math.radians(field_deg))
    z0 = -10.0

    def ray(h):
        return h - tu * (g.z_entrance_pupil - z0), z0, tu, 1.0

    lo, hi = D._pencil_edges(p, ray, a, "y", wl)
    hs = np.linspace(-0.98 * a, 0.98 * a, 40_001)
    y0 = hs - tu * (g.z_entrance_pupil - z0)
    pos = np.stack([np.zeros_like(hs), y0, np.full_like(hs, z0)], axis=1)
    d = np.broadcast_to([0.0, tu, 1.0], pos.shape)
    ok = trace_through(p, RayBatch.from_arrays(pos, d, wl), clip=True).flag == OK
    run = np.flatnonzero(ok)
    centre = run[np.argmin(np.abs(hs[run]))]
    k0, k1 = centre, centre
    while k0 > 0 and ok[k0 - 1]:
        k0 -= 1
    while k1 < hs.size - 1 and ok[k1 + 1]:
        k1 += 1
    step = hs[1] - hs[0]
    assert lo == pytest.approx(hs[k0], abs=step + 1e-4 * a) and hi == pytest.approx(hs[k1], abs=step + 1e-4 * a)
    assert lo < hi


def test_the_diagram_traces_its_pencil_edges_in_few_kernel_calls(monkeypatch):
    """Whether a ray passes needs no path: the pencils' 49-ray scans and bisections run one kernel call through
    every surface each, both ends of a pencil together and every midpoint a bisection can reach in one batch
    (main traced them surface by surface: 292 calls; one bisection step a call: 83); the drawn rays' paths
    in one batch, a call per surface."""
    import physcam.trace.trace as T

    calls = []
    real = T._run
    monkeypatch.setattr(T, "_run", lambda *a, **k: (calls.append(1), real(*a, **k))[1])
    lens_diagram(camera_state(load_lens("dgauss_50mm")))
    assert len(calls) < 20  # 15: the pencils' 2 scans and 2 bisections, the drawn rays' path
