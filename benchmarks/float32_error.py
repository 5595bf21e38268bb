"""Single against double precision tracing, on the spot and the bokeh of every bundled lens.

Run:  .venv/bin/python benchmarks/float32_error.py [--rings 48] [--rays 400000]

Spot: the spot diagram's rays (``rings`` equal-area rings over the paraxial entrance pupil
overfilled 1.3x, as ``spot_diagram``) at 0 deg and at 70 % of the widest field whose chief ray
passes, traced to the paraxial image plane in float64 and in float32 (``RayBatch.astype``);
reported: rays whose flag differs, the largest film-position difference of a ray that passes in
both, and the change of the RMS spot radius and of the centroid. Bokeh: ``bokeh_image`` of a
light 1 m from the film, on axis and at 60 % of the half-diagonal of a full-frame gate, with
``precision="single"`` against ``"double"`` (same random rays); reported: the relative L1
difference of the images, passed-ray counts and the centroid shift. Camera rays: ``camera_rays``
from 1e5 random film points (within 12 mm of the centre) and pupil samples, with Fresnel;
reported: the largest angle between the float32 and float64 directions, origin and weight
differences.
"""

from __future__ import annotations

import argparse
import math
import os

import numpy as np

from physcam.analysis.defocus.bokeh import bokeh_image
from physcam.analysis.image_quality.spot import equal_area_disk
from physcam.lens.library import list_lenses, load_lens
from physcam.optics.paraxial import gaussian
from physcam.optics.state import camera_state
from physcam.trace import RayBatch, camera_rays, paraxial_image_z, trace_to_film


def rms(out, ok):
    x, y = out.x[ok].astype(np.float64), out.y[ok].astype(np.float64)
    cx, cy = x.mean(), y.mean()
    return 1e3 * math.sqrt(((x - cx) ** 2 + (y - cy) ** 2).mean()), cx, cy


def spot_errors(lens, film, field_deg, rings):
    from physcam.analysis._chief import start_plane_z

    g = gaussian(lens)
    beam = 1.3 * g.entrance_pupil_diameter / 2
    u, v = equal_area_disk(1.0, rings)
    th = math.radians(field_deg)
    d = np.array([0.0, math.sin(th), math.cos(th)])
    z0 = min(g.z_entrance_pupil, start_plane_z(lens)) - 1.0
    back = (g.z_entrance_pupil - z0) / d[2]
    start = np.stack([beam * u, beam * v - back * d[1], np.full(u.size, z0)], axis=1)
    b = RayBatch.from_arrays(start, d[None, :])
    dd = trace_to_film(lens, b, film)
    ss = trace_to_film(lens, b.astype(np.float32), film)
    both = dd.ok & ss.ok
    if both.sum() < 10:
        return None
    r64, cx64, cy64 = rms(dd, dd.ok)
    r32, cx32, cy32 = rms(ss, ss.ok)
    dpos = np.hypot(dd.x[both] - ss.x[both], dd.y[both] - ss.y[both]).max() * 1e3
    return dict(flags=int((dd.flag != ss.flag).sum()), n=len(b), dpos_um=dpos, rms_um=r64, drms_um=abs(r32 - r64),
                dcen_um=1e3 * math.hypot(cx32 - cx64, cy32 - cy64))


def max_field(lens) -> float:
    from physcam.analysis._chief import field_limit_deg

    try:
        return field_limit_deg(lens, max_deg=60.0, wavelength_nm=lens.wavelength_nm, tol_deg=0.5)
    except Exception:
        return 0.0


def bokeh_errors(lens, film, y_mm, rays):
    kw = dict(rays=rays, pixels=128, chunk=min(rays, 250_000))
    try:
        cam = camera_state(lens, film_z=film)
        ext = bokeh_image(cam, 1000.0, 0.0, y_mm, precision="double", **(kw | dict(rays=1000, chunk=1000))).extent_mm
    except Exception as exc:  # no light reaches the film from there
        return None, str(exc)[:60]
    # both with the same window, so both draw the same random rays
    a = bokeh_image(cam, 1000.0, 0.0, y_mm, precision="double", extent_mm=ext, **kw)
    b = bokeh_image(cam, 1000.0, 0.0, y_mm, precision="single", extent_mm=ext, **kw)
    l1 = float(np.abs(a.image - b.image).sum() / a.image.sum())
    ca, cb = a.to_dict()["centroid_mm"], b.to_dict()["centroid_mm"]
    return dict(l1=l1, passed=(a.rays_passed, b.rays_passed),
                dcen_um=1e3 * math.hypot(ca[0] - cb[0], ca[1] - cb[1])), None


def camera_errors(lens, film, n=100_000):
    rng = np.random.default_rng(0)
    fxy, uv = rng.uniform(-12, 12, (n, 2)), rng.random((n, 2))
    a = camera_rays(lens, fxy, uv, film, fresnel=True)
    b = camera_rays(lens, fxy, uv, film, fresnel=True, precision="single")
    ok = a.ok & b.ok
    da, db = a.direction[ok], b.direction[ok].astype(np.float64)
    sin = np.linalg.norm(np.cross(da, db), axis=1) / np.linalg.norm(db, axis=1)  # not arccos of a dot near 1
    return dict(flags=int((a.ok != b.ok).sum()), n=n, arcsec=float(np.degrees(sin.max()) * 3600) if ok.any() else 0.0,
                dpos_um=float(np.linalg.norm(a.origin[ok] - b.origin[ok], axis=1).max() * 1e3) if ok.any() else 0.0,
                dw=float(np.abs(a.weight[ok] - b.weight[ok]).max() / a.weight[ok].max()) if ok.any() else 0.0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rings", type=int, default=48)
    ap.add_argument("--rays", type=int, default=400_000)
    args = ap.parse_args()
    print(f"load average {', '.join(f'{v:.2f}' for v in os.getloadavg())}")
    print(f"{'lens':28s} {'field':>6} {'flag diff':>10} {'max |dp| um':>12} {'RMS um':>9} {'dRMS um':>9} "
          f"{'dcentroid um':>12} | bokeh: {'y mm':>5} {'L1 diff':>8} {'passed 64/32':>17} {'dcentroid um':>12}")
    worst = dict(dpos=0.0, drms=0.0, l1=0.0, bcen=0.0, flags=0.0)
    for info in list_lenses():
        lens = load_lens(info.slug)
        try:
            film = paraxial_image_z(lens)
        except Exception as exc:
            print(f"{info.slug:28s} skipped: {exc}")
            continue
        top = max_field(lens)
        half_diag = 0.5 * math.hypot(36.0, 24.0)
        for field, y in ((0.0, 0.0), (0.7 * top, 0.6 * half_diag)):
            s = spot_errors(lens, film, field, args.rings)
            bo, why = bokeh_errors(lens, film, y * 1000.0 / max(film, 1.0), args.rays)
            line = f"{info.slug:28s} {field:6.2f} "
            if s is None:
                line += f"{'(no spot)':>57} "
            else:
                line += (f"{s['flags']:>5d}/{s['n']:<5d}{s['dpos_um']:12.5f} {s['rms_um']:9.3f} {s['drms_um']:9.5f} "
                         f"{s['dcen_um']:12.5f} ")
                worst["dpos"] = max(worst["dpos"], s["dpos_um"])
                worst["drms"] = max(worst["drms"], s["drms_um"])
                worst["flags"] = max(worst["flags"], s["flags"] / s["n"])
            if bo is None:
                line += f"| {'':5} ({why})"
            else:
                line += (f"| {y:5.1f} {bo['l1']:8.2e} {bo['passed'][0]:>8d}/{bo['passed'][1]:<8d} "
                         f"{bo['dcen_um']:12.5f}")
                worst["l1"] = max(worst["l1"], bo["l1"])
                worst["bcen"] = max(worst["bcen"], bo["dcen_um"])
            print(line)
        c = camera_errors(lens, film)
        print(f"{'':28s} camera rays: flags differing {c['flags']}/{c['n']}, direction {c['arcsec']:.3f} arcsec, "
              f"origin {c['dpos_um']:.4f} um, weight {c['dw']:.1e} (relative to the largest)")
        worst["cam_arcsec"] = max(worst.get("cam_arcsec", 0.0), c["arcsec"])
        worst["cam_um"] = max(worst.get("cam_um", 0.0), c["dpos_um"])
        worst["cam_flags"] = max(worst.get("cam_flags", 0), c["flags"])
    print(f"worst: spot ray position {worst['dpos']:.4f} um, RMS change {worst['drms']:.5f} um, flags differing "
          f"{100 * worst['flags']:.3f} % of rays; bokeh image L1 {worst['l1']:.2e}, centroid {worst['bcen']:.4f} um; "
          f"camera rays {worst['cam_arcsec']:.3f} arcsec, {worst['cam_um']:.4f} um, flags differing {worst['cam_flags']}")


if __name__ == "__main__":
    main()
