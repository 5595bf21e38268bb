"""The table of docs/lens-report.md, "Depth of field from real rays": the model's limits against the
real rays' for bundled lenses (Super 35, CoC d/1500; real blur: the diameter holding 80 % of the light,
on the axis), the lens collimated (best focus at the mark, the default) and paraxially focused.

    .venv/bin/python scripts/real_dof_table.py
"""

from __future__ import annotations

import warnings

from physcam.analysis.defocus.real_dof import real_depth_of_field
from physcam.errors import PhysCamError
from physcam.lens.library import load_lens
from physcam.onset.report import solve_lens_report
from physcam.optics.sensors import find_sensor
from physcam.optics.state import camera_state

CASES = [("dgauss_50mm", 2.8, 1000.0), ("dgauss_50mm", 2.8, 3000.0), ("dgauss_50mm", 5.6, 3000.0),
         ("tessar_50mm_f2_8", 2.8, 2000.0), ("sonnar_50mm_f1_5", 2.0, 2000.0), ("zeiss_distagon_35mm_f4", 4.0, 2000.0),
         ("zuiko_18mm_f3_5", 4.0, 1000.0), ("canon_rf_85mm_f1_2", 1.4, 3000.0), ("cooke_triplet_50mm_f4_5", 4.5, 2000.0),
         ("telephoto_250mm", 5.6, 10000.0)]


def m(v):
    return f"{v / 1000:.3f}"


def row(name: str, n: float, mark: float) -> str:
    """One row of the table: the model's limits and the real rays', collimated and paraxial."""
    sensor = find_sensor("Super 35")
    lens = load_lens(name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = solve_lens_report(focal_length_mm=None, lens=lens, sensor=sensor, fstop=n, focus_mm=mark)
    head = f"| {name} | f/{n:g} | {mark / 1000:g} | {m(r.dof.near_from_film_mm)}-{m(r.dof.far_from_film_mm)} " \
           f"| {r.dof.total_mm:.0f} |"
    try:
        cam = camera_state(lens, focus_mm=mark, fstop=n)
        c = real_depth_of_field(cam, coc_mm=r.coc_mm, measure="energy")
        p = real_depth_of_field(cam, coc_mm=r.coc_mm, measure="energy", focusing="paraxial")
    except PhysCamError as exc:
        return head + f" none: {str(exc).split(': ')[-1]} | | | |"
    return head + (f" {m(c.near_from_film_mm)}-{m(c.far_from_film_mm)} | {c.total_mm:.0f} "
                   f"| {m(p.near_from_film_mm)}-{m(p.far_from_film_mm)} | {m(p.sharpest_from_film_mm)} |")


def main() -> None:
    print("| lens | f-stop | mark (m) | model near-far (m) | model DOF (mm) | collimated near-far (m) | collimated DOF (mm) "
          "| paraxial near-far (m) | paraxial sharpest at (m) |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for name, n, mark in CASES:
        print(row(name, n, mark))


if __name__ == "__main__":
    main()
