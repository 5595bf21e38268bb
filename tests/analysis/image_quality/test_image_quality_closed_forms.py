"""Wavefront, PSF and MTF against closed forms worked by hand (tests/analysis/_image_quality.py):
a lens that images a point perfectly gives the textbook MTF of a circular pupil; moving its film
gives pure defocus of known waves, whose OPD, MTF (Hopkins), Strehl ratio (exact and Marechal)
and geometric MTF (a uniform disk) are known."""

from __future__ import annotations

import math

import numpy as np
import pytest

from physcam.analysis.image_quality.mtf import diffraction_limited_mtf, geometric_mtf, mtf, through_focus_mtf
from physcam.analysis.image_quality.psf import psf
from physcam.analysis.image_quality.wavefront import noll_indices, wavefront, zernike_noll
from physcam.optics.state import as_designed
from physcam.trace.aperture import Aperture

from _image_quality import (F_MM, defocus_opd_exact, defocus_otf, disk_mtf, perfect_lens, reference_sine, sin_u,
                             strehl_defocus, textbook_mtf)

WL = 550.0
LAM_MM = WL * 1e-6
LENS = perfect_lens()


def _exit_pupil_to_focus():
    """Distance (mm) from the paraxial exit pupil to F, by hand. The flat face images the stop (5 mm
    in front of it, in air) 5 n mm in front of it, in glass: 5 n + 5 mm in front of the vertex. The
    curved surface (n -> 1, radius R = -(n - 1) f) images that point at s' with 1/s' = (1 - n)/R + n/s,
    s = -(5 n + 5); F lies f behind the vertex."""
    n = 1.5
    s = -(5 * n + 5)
    r = -(n - 1) * F_MM
    s_img = 1.0 / ((1.0 - n) / r + n / s)
    return F_MM - s_img


@pytest.mark.parametrize("fstop", [8.0, 16.0])
def test_perfect_lens_gives_the_textbook_mtf(fstop):
    wf = wavefront(as_designed(LENS, fstop=fstop), 0.0, wavelength_nm=WL)
    assert np.abs(wf.opd_waves).max() < 1e-6  # stigmatic: every ray through F
    h = F_MM / (2 * fstop)  # the entrance pupil (the stop) radius
    cutoff_real = 2 * float(sin_u(h)) / LAM_MM  # 2 NA' / lambda with the real marginal ray
    nu = np.linspace(0.0, cutoff_real, 41)
    m = mtf(as_designed(LENS, fstop=fstop), 0.0, frequencies=nu, wavelengths_nm=[WL])
    ref = textbook_mtf(nu / cutoff_real)
    assert np.abs(m.tangential - ref).max() < 0.005
    assert np.abs(m.sagittal - ref).max() < 0.005
    # against the paraxial cut-off 1 / (lambda N) as well: the real marginal ray is 0.58 % (f/8) and
    # 0.15 % (f/16) flatter than h / f, which stays inside the tolerance
    ref_par = textbook_mtf(nu * LAM_MM * fstop)
    assert np.abs(m.tangential - ref_par).max() < 0.005
    # the diffraction limit the curve reports is that of its own (unaberrated) pupil
    assert np.allclose(m.diffraction_limit_tangential, m.tangential, atol=1e-9)
    assert m.cutoff_tangential_lpmm == pytest.approx(cutoff_real, rel=0.01)
    # Strehl of a perfect pupil
    assert psf(as_designed(LENS, fstop=fstop), 0.0, wavelength_nm=WL).strehl == pytest.approx(1.0, abs=1e-3)


def test_diffraction_limited_mtf_closed_form():
    assert diffraction_limited_mtf(0.0, 100.0) == 1.0
    assert diffraction_limited_mtf(50.0, 100.0) == pytest.approx((2 / math.pi) * (math.acos(0.5) - 0.5 * math.sqrt(0.75)))
    assert diffraction_limited_mtf(150.0, 100.0) == 0.0


def _defocus_for(w20_waves, fstop):
    """Film shift (mm) giving exactly w20 waves at the pupil's rim (the exact OPD of a refocused
    sphere, solved from its first-order value dz (1 - cos u') by fixed-point steps)."""
    s = float(sin_u(F_MM / (2 * fstop)))
    R = _exit_pupil_to_focus()
    target = w20_waves * LAM_MM
    dz = target / (1.0 - math.sqrt(1.0 - s * s))
    for _ in range(20):
        dz *= target / float(defocus_opd_exact(s, R, dz))
    return dz


def test_pure_defocus_opd_is_the_closed_form():
    fstop = 16.0
    dz = _defocus_for(0.5, fstop)
    wf = wavefront(as_designed(LENS, fstop=fstop), 0.0, wavelength_nm=WL, defocus_mm=dz)
    h = np.hypot(wf.x, wf.y) * F_MM / (2 * fstop)  # entrance heights (the stop is the entrance pupil)
    R = _exit_pupil_to_focus()
    expected = defocus_opd_exact(sin_u(h), R, dz) / LAM_MM
    assert np.abs(wf.opd_waves - expected).max() < 2e-4
    assert wf.pv_waves == pytest.approx(0.5, abs=2e-3)
    # rho^2 has mean 1/2 and variance 1/12 over the disk: RMS = W20 / sqrt(12)
    assert wf.rms_waves == pytest.approx(0.5 / math.sqrt(12), rel=0.01)
    # Noll: W20 rho^2 = W20/2 Z1 + W20/(2 sqrt 3) Z4
    assert wf.zernike[3] == pytest.approx(0.5 / (2 * math.sqrt(3)), rel=0.01)
    assert abs(wf.zernike[10]) < 2e-3  # no spherical aberration beyond the tiny rho^4 of a large wave


def _cutoff_at(fstop, dz):
    """Cut-off (lp/mm) of the plane dz past the focus: the pupil seen from that plane's centre."""
    return 2 * float(reference_sine(sin_u(F_MM / (2 * fstop)), _exit_pupil_to_focus(), dz)) / LAM_MM


@pytest.mark.parametrize("w20", [0.5, 1.0])
def test_pure_defocus_mtf_matches_hopkins(w20):
    fstop = 16.0
    dz = _defocus_for(w20, fstop)
    cutoff = _cutoff_at(fstop, dz)
    nu = np.linspace(0.0, 0.96 * cutoff, 13)
    m = mtf(as_designed(LENS, fstop=fstop), 0.0, frequencies=nu, wavelengths_nm=[WL], defocus_mm=dz)
    ref = np.array([abs(defocus_otf(v / cutoff, w20)) for v in nu])
    assert np.abs(m.tangential - ref).max() < 0.005
    assert np.abs(m.sagittal - ref).max() < 0.005


@pytest.mark.parametrize("w20", [0.1, 0.5])
def test_pure_defocus_strehl_exact_and_marechal(w20):
    fstop = 16.0
    p = psf(as_designed(LENS, fstop=fstop), 0.0, wavelength_nm=WL, defocus_mm=_defocus_for(w20, fstop))
    assert p.strehl == pytest.approx(strehl_defocus(w20), abs=0.005)
    if w20 <= 0.1:  # Marechal: exp(-(2 pi sigma)^2), sigma = W20 / sqrt(12)
        assert p.strehl == pytest.approx(math.exp(-(2 * math.pi * w20 / math.sqrt(12)) ** 2), abs=0.003)


def test_through_focus_is_defocus_at_each_film_position():
    fstop = 16.0
    dzs = [-_defocus_for(0.5, fstop), 0.0, _defocus_for(0.25, fstop), _defocus_for(0.5, fstop)]
    cutoff = 2 * float(sin_u(F_MM / (2 * fstop))) / LAM_MM
    freqs = [0.1 * cutoff, 0.3 * cutoff]
    tf = through_focus_mtf(as_designed(LENS, fstop=fstop), 0.0, freqs, defocus_mm=dzs, wavelengths_nm=[WL])
    for j, dz in enumerate(dzs):
        # the film in front of the focus (dz < 0) gives negative defocus of the same size
        w20 = float(defocus_opd_exact(sin_u(F_MM / (2 * fstop)), _exit_pupil_to_focus(), dz)) / LAM_MM
        for k, f in enumerate(freqs):
            assert tf.tangential[k, j] == pytest.approx(abs(defocus_otf(f / _cutoff_at(fstop, dz), w20)), abs=0.005)
    best = tf.best_focus_mm()
    assert all(v == 0.0 for v in best.values())


def test_polychromatic_mtf_of_a_perfect_lens_is_the_weighted_sum():
    # dispersionless: each wavelength is diffraction limited with its own cut-off 2 NA / lambda, and
    # every OTF is real and positive, so the weighted sum of the textbook curves is exact
    fstop = 16.0
    wls, wts = [450.0, 550.0, 650.0], [1.0, 2.0, 1.0]
    s = float(sin_u(F_MM / (2 * fstop)))
    nu = np.linspace(0.0, 2 * s / (650e-6), 21)
    m = mtf(as_designed(LENS, fstop=fstop), 0.0, frequencies=nu, wavelengths_nm=wls, weights=wts)
    ref = sum(w * textbook_mtf(nu * (lam * 1e-6) / (2 * s)) for lam, w in zip(wls, wts)) / sum(wts)
    assert np.abs(m.tangential - ref).max() < 0.005


def test_geometric_mtf_of_a_large_defocus_is_a_uniform_disk():
    fstop = 16.0
    dz = _defocus_for(8.0, fstop)
    h = F_MM / (2 * fstop)
    s = float(sin_u(h))
    radius = dz * s / math.sqrt(1 - s * s)  # the marginal ray dz past F
    first_zero = 3.8317 / (2 * math.pi * radius)
    nu = np.linspace(0.0, 1.6 * first_zero, 21)
    g = geometric_mtf(as_designed(LENS, fstop=fstop), 0.0, frequencies=nu, wavelengths_nm=[WL], defocus_mm=dz,
                      pupil_samples=128)
    ref = disk_mtf(nu, radius)
    assert np.abs(g.tangential - ref).max() < 0.01
    assert np.abs(g.sagittal - ref).max() < 0.01


def test_hexagonal_iris_sets_the_pupil_shape():
    # f/16 with blades is the round f/16 iris's area (docs/conventions.md): a regular hexagon of corner
    # radius R has area (3 sqrt 3 / 2) R^2, so its corners lie sqrt(2 pi / (3 sqrt 3)) = 1.0996 round
    # radii out and it lights the whole of the round pupil's area (inscribed in the round iris, the old
    # convention, it lit 0.827 of it)
    wf = wavefront(as_designed(LENS, fstop=16.0, aperture=Aperture(nsides=6)), 0.0, wavelength_nm=WL)
    assert wf.lit_fraction == pytest.approx(1.0, abs=0.004)
    # along x a vertex reaches the corner radius, along y the flats sit at cos 30 of it: the tangential
    # cut-off is 0.866 of the sagittal one
    m = mtf(as_designed(LENS, fstop=16.0, aperture=Aperture(nsides=6)), 0.0, wavelengths_nm=[WL])
    assert m.cutoff_tangential_lpmm / m.cutoff_sagittal_lpmm == pytest.approx(math.cos(math.pi / 6), abs=0.01)


def test_noll_ordering_and_orthonormality():
    table = [(0, 0), (1, 1), (1, -1), (2, 0), (2, -2), (2, 2), (3, -1), (3, 1), (3, -3), (3, 3), (4, 0)]
    assert [noll_indices(j) for j in range(1, 12)] == table  # Noll (1976), table 1
    # the first 21 terms are orthonormal over the unit disk: (1/pi) int Z_i Z_j dA = delta_ij
    t, w = np.polynomial.legendre.leggauss(40)
    r = 0.5 * (t + 1)
    wr = 0.5 * w * r
    th = np.linspace(0, 2 * np.pi, 96, endpoint=False)
    R, TH = np.meshgrid(r, th, indexing="ij")
    W = (wr[:, None] * np.full(th.size, 2 * np.pi / th.size)[None, :]) / np.pi
    Z = np.stack([zernike_noll(j, R, TH).ravel() for j in range(1, 22)])
    G = (Z * W.ravel()) @ Z.T
    assert np.allclose(G, np.eye(21), atol=1e-9)
