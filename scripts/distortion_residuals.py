"""Residuals of every fitted distortion model on every bundled spherical lens (docs/distortion.md).

Run: .venv/bin/python scripts/distortion_residuals.py > /tmp/table.md
Each lens at a 2 m focus (infinity where it cannot focus that close) on the largest of these
sensors whose corners its chief rays reach, 2048 pixels wide.
"""

from __future__ import annotations

import math

from physcam.analysis.distortion.models import fit_models, samples_from_field
from physcam.analysis.distortion.stmap import distortion_field
from physcam.errors import PhysCamError
from physcam.lens.library import list_lenses, load_lens
from physcam.optics.state import camera_state

SENSORS = [("36 x 24", 36.0, 24.0), ("Super 35 24.89 x 18.66", 24.89, 18.66), ("16 mm 12.52 x 7.41", 12.52, 7.41),
           ("2/3 in 8.8 x 6.6", 8.8, 6.6), ("1/3 in 4.8 x 3.6", 4.8, 3.6), ("1.6 x 1.2", 1.6, 1.2)]


def main() -> None:
    print("| lens | sensor | focus | max distortion px | Brown D-U RMS / max px | Brown U-D RMS / max px "
          "| 3DE4 Radial Std 4 RMS / max px | USD standard RMS / max px |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for rec in list_lenses():
        name = rec.slug
        lens = load_lens(name)
        if lens.is_anamorphic:
            continue
        done = False
        for focus in (2000.0, math.inf):
            for label, w, h in SENSORS:
                try:
                    res = distortion_field(camera_state(lens, focus_mm=focus, sensor_mm=(w, h)),
                                           width_px=2048, height_px=round(2048 * h / w), maps=False)
                except PhysCamError:
                    continue
                fits = fit_models(samples_from_field(res), ("brown", "3de4", "usd"))
                cells = " | ".join(f"{f.rms_residual_px:.3f} / {f.max_residual_px:.3f}"
                                   + ("" if f.acceptable else " (not good)") for f in fits)
                fl = "inf" if math.isinf(focus) else f"{focus / 1000:g} m"
                print(f"| {name} | {label} | {fl} | {res.max_distortion_px:.1f} | {cells} |")
                done = True
                break
            if done:
                break
        if not done:
            print(f"| {name} | (covers none of the sensors) | | | | | | |")


if __name__ == "__main__":
    main()
