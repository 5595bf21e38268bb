"""Issue 47: the README's MTF chart (`physcam mtf --lens dgauss_50mm`) does less work for the same numbers.

Structural guards (not timings, docs/performance.md has those): a lens whose prescription gives no
dispersion aims its chief rays once, not once per wavelength, and its wavelengths share one sub-cell
layout; the OPD phasors agree with the exponential by other means (closed-form points, numpy's
complex exp); the direct lag sums agree with the FFT autocorrelation of the same pupil.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.analysis import _chief
from physcam.analysis.image_quality import _pupil as P
from physcam.analysis.image_quality import _sampling as S
from physcam.analysis.image_quality.mtf import WHITE_LIGHT_NM, mtf_chart
from physcam.lens.library import load_lens
from physcam.optics.state import camera_state


def _count_aims(monkeypatch) -> list:
    calls = []
    aim = _chief.aim_from_infinity

    def counted(*args, **kwargs):
        calls.append(kwargs.get("wavelength_nm"))
        return aim(*args, **kwargs)

    monkeypatch.setattr(_chief, "aim_from_infinity", counted)
    return calls


@pytest.mark.parametrize("slug, aims", [("dgauss_50mm", 1), ("zuiko_18mm_f3_5", 3)])
def test_a_chart_aims_the_chief_rays_once_per_distinct_set_of_indices(monkeypatch, slug, aims):
    # dgauss_50mm's prescription gives no dispersion: its d, F and C chief rays are one set of rays
    # (main aimed them three times); the Zuiko's glasses disperse, so each line is aimed on its own
    calls = _count_aims(monkeypatch)
    chart = mtf_chart(camera_state(load_lens(slug)), image_heights_mm=[4.0], frequencies=[20.0])
    assert len(calls) == aims
    assert chart.sagittal.shape == (1, 1) and np.isfinite(chart.sagittal).all()


def test_the_wavelengths_of_a_lens_without_dispersion_share_one_sub_cell_layout():
    cam = camera_state(load_lens("dgauss_50mm"))
    fp = S.field_pupils(cam, 10.0, wavelengths_nm=WHITE_LIGHT_NM, min_frequency=10.0, waves_per_cell=S.WAVES_PER_CELL_MTF)
    ref = fp.reference_point(0.0)
    pfs = [fp.pupil(i, 0.0, ref) for i in range(3)]
    assert P._sub_cells(fp.traces[0]) is P._sub_cells(fp.traces[1]) is P._sub_cells(fp.traces[2])
    # the shared layout gives each wavelength the pupil it would get from a layout of its own
    for pf in pfs[1:]:
        alone = dataclasses.replace(pf._pt, shared={})
        own = P.pupil_function(alone, P.wavefront_on(alone, fp.setup.film_z, ref))
        assert np.array_equal(P.sub_cell_pupil(own), P.sub_cell_pupil(pf))
        assert (own.slope_x, own.slope_y) == (pf.slope_x, pf.slope_y)
        # the wavefront's geometry and the cells' sums, shared too: the same numbers as computed alone
        assert np.array_equal(own.opd, pf.opd) and np.array_equal(own.amplitude0, pf.amplitude0)
        assert np.array_equal(own._ws.opd_waves, pf._ws.opd_waves)


def test_the_wavelengths_of_a_dispersive_lens_keep_their_own_traces():
    # review of round 13: the sharing is keyed on each medium's index at the wavelength; the Zuiko's
    # glasses disperse, so its d, F and C pupils must each be traced and laid out on their own
    cam = camera_state(load_lens("zuiko_18mm_f3_5"))
    fp = S.field_pupils(cam, 10.0, wavelengths_nm=WHITE_LIGHT_NM, min_frequency=10.0, waves_per_cell=S.WAVES_PER_CELL_MTF)
    ref = fp.reference_point(0.0)
    pfs = [fp.pupil(i, 0.0, ref) for i in range(3)]
    cells = [P._sub_cells(t) for t in fp.traces]
    assert cells[0] is not cells[1] and cells[1] is not cells[2] and cells[0] is not cells[2]
    assert not np.array_equal(pfs[0].opd, pfs[1].opd) and not np.array_equal(pfs[1].opd, pfs[2].opd)


@settings(max_examples=50, deadline=None)
@given(st.lists(st.tuples(*[st.floats(-1e6, 1e6, allow_subnormal=False)] * 3).filter(lambda d: any(d)),
                min_size=1, max_size=20))
def test_unit_directions_are_what_a_ray_batch_makes_of_them(dirs):
    # the pupil engine makes its batches of unit_directions' columns as they are: they must be the
    # directions RayBatch.from_columns would have made, to the bit
    from physcam.trace import RayBatch

    d = np.array(dirs, dtype=float)
    got = P.unit_directions(d[:, 0], d[:, 1], d[:, 2])
    want = RayBatch.from_columns(*np.zeros((3, len(d))), d[:, 0], d[:, 1], d[:, 2])
    for g, w in zip(got, (want.L, want.M, want.N)):
        assert np.array_equal(g, w)
    one = P.unit_directions(*(d[:1, k] for k in range(3)))  # a beam's one direction, normalised alone
    assert all(np.array_equal(a, b[:1]) for a, b in zip(one, got))


def test_the_phasors_at_closed_form_points():
    w = np.array([[0.0, 0.25, 0.5, 0.75], [-0.25, 0.125, 1.0, -3.5]])
    r = np.sqrt(0.5)
    want = np.array([[1, -1j, -1, 1j], [1j, r - 1j * r, 1, -1]])
    assert np.abs(P.unit_phasors(w) - want).max() < 1e-15


@settings(max_examples=25, deadline=None)
@given(st.integers(1, 40), st.integers(1, 300), st.floats(1e-3, 200.0), st.booleans(), st.integers(0, 2 ** 32 - 1))
def test_the_phasors_are_the_complex_exponential(rows, cols, scale, column_major, seed):
    # against numpy's exp(-2 pi i w): both round 2 pi w, so they differ by a few ulps of that phase
    w = np.random.default_rng(seed).normal(0.0, scale, (rows, cols))
    if column_major:
        w = np.asfortranarray(w)
    got = P.unit_phasors(w)
    assert got.flags.f_contiguous == column_major or rows == 1 or cols == 1
    err = np.abs(got - np.exp(-2j * np.pi * w))
    assert (err <= 2e-15 * (1.0 + np.abs(w))).all()


@pytest.mark.parametrize("axis", [0, 1])
def test_the_direct_lag_sums_are_the_fft_autocorrelation(axis):
    cam = camera_state(load_lens("dgauss_50mm"))  # a vignetted field, its phase a few waves per cell
    pf = S.field_pupils(cam, 16.0, wavelengths_nm=[486.1327], pupil_samples=96, check=False).pupil(0)
    by_fft = P.otf_lags(pf, axis)  # Wiener-Khinchin over the whole pupil at once
    for k in (0, 1, 7, 40, 151):
        direct = P._lag(dataclasses.replace(pf, _lags={}), k, axis, True)
        assert abs(direct - by_fft[k]) < 1e-12
    assert abs(by_fft[0] - 1.0) < 1e-12


def test_a_fields_pupil_is_traced_once_for_its_wavefront_and_its_mtf(monkeypatch):
    # `physcam mtf --field` asks the wavefront, the PSF and the MTF of one field: main traced the same
    # 64-cell pupil for each; now the last camera's pupils are kept (P.RECENT_RAYS)
    from physcam.analysis.image_quality.mtf import mtf
    from physcam.analysis.image_quality.wavefront import wavefront

    jobs = []
    trace = P._trace_pupils

    def counted(js, st, tracer):
        jobs.extend((f.field_deg, f.wavelength_nm, n) for f, n, _ in js)
        return trace(js, st, tracer)

    monkeypatch.setattr(P, "_trace_pupils", counted)
    cam = camera_state(load_lens("dgauss_50mm"), fstop=4.0)
    wavefront(cam, 5.0, wavelength_nm=WHITE_LIGHT_NM[0])
    kept = mtf(cam, 5.0, frequencies=[10.0, 30.0])
    assert jobs == [(5.0, WHITE_LIGHT_NM[0], 64)]
    P._recent.clear()  # the same MTF traced afresh: the kept rays change nothing
    fresh = mtf(cam, 5.0, frequencies=[10.0, 30.0])
    assert len(jobs) == 2
    assert np.array_equal(kept.sagittal, fresh.sagittal) and np.array_equal(kept.tangential, fresh.tangential)
    mtf(camera_state(load_lens("dgauss_50mm"), fstop=4.0), 5.0, frequencies=[10.0])  # another camera: traced
    assert len(jobs) == 3


def test_the_heap_keeps_its_freed_pages_in_the_program_only():
    # the library leaves a caller's allocator alone (Blender, a notebook): no malloc setting without the program
    from physcam import _program

    cam = camera_state(load_lens("dgauss_50mm"), fstop=4.0)
    P.setup(cam)
    assert not _program.RUNNING and _program.roomy_heap() is False
    # the program (a fresh process, as `physcam` starts): the pupil engine's setup asks glibc for the pad
    import os
    import subprocess
    import sys

    if not sys.platform.startswith("linux") or not os.confstr("CS_GNU_LIBC_VERSION").startswith("glibc"):
        pytest.skip("M_TOP_PAD is glibc's")
    code = ("from physcam import _program\n_program.start()\nfrom physcam.analysis.image_quality import _pupil as P\n"
            "from physcam.lens.library import load_lens\nfrom physcam.optics.state import camera_state\n"
            "assert not _program._roomy\nP.setup(camera_state(load_lens('dgauss_50mm'), fstop=4.0))\n"
            "print(_program._roomy)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
    assert out.stdout.strip() == "True"
