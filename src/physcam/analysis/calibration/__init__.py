"""Calibration: a lens characterized from chart photographs (pinhole, principal point, distortion,
breathing), relative illumination from flat fields, the calibration sheet, and the measurement against
physcam's prediction (docs/calibrate.md)."""
