"""Issue 39 item 7: the Huygens MTF never returns an impossible answer, and is normalised by the pupil's power.

On ray-optics' test file US00583336-2-scaled.zmx at 21 degrees `huygens_mtf` returned energy_in_grid
3.44 and T 0.083/0.122/0.055 (FFT 0.314/0.152/0.057) with no warning, where `physcam mtf --method
huygens` refuses the field. Its quadratic phase's power series was cut at five terms on a grid that
needed thirty; the grid is now summed in quadrants, and the API refuses what the CLI refuses.
The MTF was divided by the PSF grid's sum, so power outside the grid raised every frequency (+0.003
on dgauss_50mm's axis); it is now divided by the field's power (Parseval). Oracles: optiland 0.6.3's
FFT MTF (tests/data/optiland_mtf_dgauss.json) and the exact wavelet sum ray by ray.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from physcam.analysis.image_quality import _sampling
import physcam.analysis.image_quality.huygens as H
from physcam.analysis.image_quality.huygens import _field_sum, _wavelets, huygens_mtf
from physcam.cli import main
from physcam.errors import OpticsError
from physcam.lens.library import load_lens
from physcam.optics.state import as_designed, camera_state

DATA = Path(__file__).resolve().parents[2] / "data"
PATENT = DATA / "zemax" / "US00583336-2-scaled.zmx"


def _terms_needed(eps, tol=1e-6):
    """Terms of exp(-i x)'s series past the first for |x| <= eps until the next is below ``tol``."""
    n = 0
    while eps ** (n + 1) / math.factorial(n + 1) > tol:
        n += 1
    return n


def test_the_api_refuses_what_the_cli_refuses(capsys):
    from physcam.cli.mtf import CLI_MAX_PUPIL_SAMPLES
    from physcam.lens.formats import read_lens

    assert getattr(H, "MAX_PUPIL_SAMPLES", None) == CLI_MAX_PUPIL_SAMPLES
    assert main(["mtf", "--lens", str(PATENT), "--field", "21", "--method", "huygens"]) == 2
    said = capsys.readouterr().err.strip().splitlines()[-1].removeprefix("physcam: error: ")
    with pytest.raises(OpticsError) as exc:
        huygens_mtf(read_lens(PATENT), 21.0, frequencies=[10.0, 20.0, 40.0])
    assert str(exc.value) == said and "more than 512" in said


def test_mtf_is_divided_by_the_pupils_power():
    """dgauss_50mm at f/8 on axis, d line: optiland's FFT MTF within 5e-4 (the grid's sum read +0.003)."""
    oracle = json.loads((DATA / "optiland_mtf_dgauss.json").read_text())
    case = next(c for c in oracle["cases"] if c["fstop"] == 8.0 and c["field_deg"] == 0.0)
    t, s, p = huygens_mtf(as_designed(load_lens("dgauss_50mm"), fstop=8.0), 0.0, frequencies=[0.0, 10.0, 20.0, 40.0],
                          wavelengths_nm=[oracle["wavelength_nm"]])
    assert np.abs(t[1:] - case["mtf_tangential"]).max() < 5e-4
    assert np.abs(s[1:] - case["mtf_sagittal"]).max() < 5e-4
    assert t[0] == pytest.approx(p.energy_in_grid, rel=1e-9) and p.energy_in_grid < 1.0  # the power it holds


def test_a_wide_grid_is_summed_in_quadrants_as_one_long_series(monkeypatch):
    """A grid 0.56 mm across around dgauss_50mm's 14 degree field: kappa Q^2 reaches about 2 radians, where five
    terms of exp(-i kappa Q^2)'s series leave an error of 2^6 / 6! = 9 %. Summed in quadrants (each expanded about
    its own centre) it equals the same sum with the series taken as far as it needs (60 terms allowed, one tile)."""
    lens = load_lens("dgauss_50mm")
    fp = _sampling.field_pupils(camera_state(lens, fstop=4.0), 14.0, wavelengths_nm=[587.5618], pupil_samples=48)
    ref = fp.reference_point(0.0)
    A, u, R, C, _, n_img = _wavelets(fp, 0, 0.0, ref)
    lam = 587.5618e-6
    g = (np.arange(15) - 7) * 0.04
    kappa = math.pi * n_img / (lam * R)
    q = float(np.abs(u[:, 0]).max() * g.max() + np.abs(u[:, 1]).max() * g.max())
    assert _terms_needed(kappa * q * q) > H.MAX_SERIES_ORDER  # the whole grid needs more terms than allowed
    tiled = np.abs(_field_sum(A, u, R, n_img, lam, np.zeros(3), g, g, (0.0, 0.0))) ** 2
    monkeypatch.setattr(H, "MAX_SERIES_ORDER", 60)
    assert _terms_needed(kappa * q * q) <= 60
    long = np.abs(_field_sum(A, u, R, n_img, lam, np.zeros(3), g, g, (0.0, 0.0))) ** 2
    assert np.abs(tiled - long).max() < 1e-6 * long.max()
