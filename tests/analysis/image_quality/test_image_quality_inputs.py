"""Bad input to the image-quality analyses is a clear PhysCamError, not a silent wrong curve (issue 16),
and properties every MTF keeps."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.analysis.image_quality.mtf import geometric_mtf, mtf, mtf_chart, through_focus_mtf
from physcam.analysis.image_quality.psf import psf
from physcam.analysis.image_quality.wavefront import noll_indices, wavefront
from physcam.errors import InputError, OpticsError, PhysCamError
from physcam.lens.library import load_lens
from physcam.lens.prescription import LensMetadata, Medium, Prescription, Surface
from physcam.optics.state import as_designed

DGAUSS = load_lens("dgauss_50mm")


def window_lens():
    """A stop, 50 mm of air, then a 2 mm-radius window before the lens: on axis light passes; at 20
    degrees the beam is 50 tan 20 = 18 mm off axis at the window, wholly outside its rim."""
    return Prescription(
        (Surface(0.0, 50.0, semi_diameter=5.0, kind="stop"), Surface(0.0, 2.0, Medium(1.5, 0.0), 2.0, kind="flat"),
         Surface(0.0, 5.0, semi_diameter=2.0, kind="flat"), Surface(50.0, 3.0, Medium(1.5, 0.0), 10.0),
         Surface(0.0, 95.0, semi_diameter=10.0, kind="flat")),
        LensMetadata(name="window"),
    ).validate()


def test_pupil_sampling_too_coarse_for_the_frequency():
    # at f/2.8 one cell of a 16-cell grid spans ~42 lp/mm: 2 lp/mm would be read inside one cell
    with pytest.raises(InputError, match=r"too coarse.*lp/mm.*use at least \d+ pupil samples"):
        mtf(as_designed(DGAUSS, fstop=2.8), 0.0, frequencies=[2.0], pupil_samples=16)
    # left to itself the grid grows until it is fine enough
    m = mtf(as_designed(DGAUSS, fstop=2.8), 0.0, frequencies=[2.0])
    assert m.pupil_samples >= 184 and 0.99 < m.tangential[0] <= 1.0


def test_pupil_sampling_too_coarse_for_the_wavefront():
    # f/2.8 at 14 degrees: 6 waves peak-to-valley, 0.84 waves between cells of a 64-cell grid
    with pytest.raises(InputError, match="too coarse.*waves between neighbouring cells"):
        psf(as_designed(DGAUSS, fstop=2.8), 14.0, pupil_samples=64)


def test_field_outside_the_lens_field():
    with pytest.raises(OpticsError, match="outside the field.*chief rays pass up to"):
        mtf(DGAUSS, 60.0, frequencies=[10.0])
    with pytest.raises(OpticsError, match="outside the image circle"):
        mtf_chart(DGAUSS, image_heights_mm=[60.0])


def test_fully_vignetted_field():
    win = window_lens()
    assert mtf(win, 0.0, frequencies=[10.0]).tangential[0] > 0.5
    with pytest.raises(OpticsError, match="fully vignetted"):
        mtf(win, 20.0, frequencies=[10.0])
    with pytest.raises(OpticsError, match="fully vignetted"):
        wavefront(DGAUSS, 35.0)  # dgauss.50mm wide open: its rims block everything at 35 degrees


@pytest.mark.parametrize("call, err", [
    (lambda: mtf(DGAUSS, float("nan")), InputError),
    (lambda: mtf(DGAUSS, 0.0, frequencies=[10.0, float("inf")]), InputError),
    (lambda: mtf(DGAUSS, 0.0, frequencies="10"), InputError),
    (lambda: mtf(DGAUSS, 0.0, wavelengths_nm=[100.0]), InputError),
    (lambda: mtf(DGAUSS, 0.0, wavelengths_nm=[550.0, 600.0], weights=[1.0]), InputError),
    (lambda: mtf(DGAUSS, 0.0, weights=[-1.0]), InputError),
    (lambda: mtf(as_designed(DGAUSS, fstop=1.0), 0.0), OpticsError),  # faster than the lens opens
    (lambda: mtf(DGAUSS, 0.0, pupil_samples=8), InputError),
    (lambda: psf(DGAUSS, 0.0, padding=1), InputError),
    (lambda: wavefront(DGAUSS, 0.0, zernike_terms=0), InputError),
    (lambda: through_focus_mtf(DGAUSS, 0.0, defocus_mm=[float("nan")]), InputError),
    (lambda: mtf_chart(DGAUSS, n_fields=1), InputError),
    (lambda: mtf_chart(DGAUSS, max_image_height_mm=-1.0), InputError),
    (lambda: noll_indices(0), InputError),
    (lambda: mtf("dgauss_50mm", 0.0), TypeError),
])
def test_bad_arguments_are_refused_with_a_sentence(call, err):
    with pytest.raises(err) as info:
        call()
    assert isinstance(info.value, (PhysCamError, TypeError)) and str(info.value)


@settings(max_examples=4)
@given(field=st.floats(0.0, 16.0), fstop=st.sampled_from([2.8, 5.6, 11.0]), nu=st.floats(5.0, 80.0))
def test_mtf_never_beats_the_diffraction_limit_of_its_pupil(field, fstop, nu):
    # |sum P P*| <= sum |P||P*| (triangle inequality) at every frequency, wavelength by wavelength
    m = mtf(as_designed(DGAUSS, fstop=fstop), field, frequencies=[0.0, nu], wavelengths_nm=[587.5618, 486.1327])
    for curve, limit in ((m.tangential, m.diffraction_limit_tangential), (m.sagittal, m.diffraction_limit_sagittal)):
        assert curve[0] == pytest.approx(1.0)
        assert np.all((curve >= 0) & (curve <= limit + 1e-9))
    assert np.isfinite(m.tangential).all()


def test_geometric_and_diffraction_mtf_agree_where_aberrations_dominate():
    # f/2 on axis: about 1.5 waves RMS of spherical aberration; at low frequency the geometric
    # approximation and the diffraction MTF meet (Smith, Modern Optical Engineering, 11.9)
    cam = as_designed(DGAUSS, fstop=2.03)
    d = mtf(cam, 0.0, frequencies=[5.0, 10.0])
    g = geometric_mtf(cam, 0.0, frequencies=[5.0, 10.0])
    assert np.abs(d.tangential - g.tangential).max() < 0.05


def test_strehl_tracks_marechal_for_a_small_aberration():
    cam = as_designed(DGAUSS, fstop=8.0)
    wf = wavefront(cam, 14.0)
    p = psf(cam, 14.0)
    assert wf.rms_to_centroid_waves < 0.1
    assert p.strehl == pytest.approx(wf.strehl_marechal, abs=0.01)
    assert p.image.max() == pytest.approx(p.strehl, rel=0.05)  # the FFT grid's peak is near the refined one
    assert math.isfinite(p.airy_radius_um) and p.pixel_um[0] > 0


def test_lateral_colour_costs_tangential_contrast_in_white_light():
    # Cooke triplet (real glasses) at 15 degrees: each wavelength's chief ray lands at its own height,
    # so against the primary's chief ray the F and C OTFs carry a phase along y. The polychromatic
    # tangential MTF (a complex sum) falls below the mean of the monochromatic ones; along x there
    # is no lateral colour (the field lies in the Y meridian), and the sagittal sums agree.
    lens = load_lens("cooke_triplet_50mm_f4_5")
    wl = (587.5618, 486.1327, 656.2725)
    poly = mtf(lens, 15.0, frequencies=[40.0], wavelengths_nm=wl)
    mono = [mtf(lens, 15.0, frequencies=[40.0], wavelengths_nm=[w]) for w in wl]
    mean_t = sum(m.tangential[0] for m in mono) / 3
    mean_s = sum(m.sagittal[0] for m in mono) / 3
    assert poly.tangential[0] < mean_t - 0.002
    assert poly.sagittal[0] == pytest.approx(mean_s, abs=0.002)
