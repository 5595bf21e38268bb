"""What physcam can say about the T-stops of the bundled cine lenses, and what it cannot (issue 44).

A T-stop is the f-number of a perfect lens passing the same light on axis: T = N / sqrt(tau), tau the
axial transmittance (ISO 517). physcam's tracer carries the Fresnel losses of every surface with the
file's coating model (physcam.trace.fresnel: 0.25 % residual reflectance per glass-air surface for
"multi") and no absorption in the glass, so physcam's T-stop is a Fresnel-only estimate, faster than
any real lens's. No maker's T-stop for these lenses was reached at a citable page (docs/lens-library.md,
"T-stops"): none is written in the files, and each file's ``maker_data`` says so with the estimate.

The oracle: the transmittance of a ray along the axis, worked by hand from the Fresnel equations at
normal incidence (Hecht, *Optics*, 5th ed., eq. 4.47: R = ((n1 - n2) / (n1 + n2))^2) and the coating
model as docs/ray-tracing.md states it, multiplied over the surfaces; the tracer's weight for a ray
1e-3 of the front semi-diameter off the axis must equal it.
"""

import math
import re

import pytest

from physcam.lens.library import load_lens
from physcam.lens.provenance import provenance_of
from physcam.optics.glass import medium_index
from physcam.optics.paraxial import gaussian
from physcam.trace.rays import RayBatch
from physcam.trace.trace import trace_through

CINE_PRIMES = ("arri_zeiss_master_prime_50mm", "arri_zeiss_master_prime_75mm", "arri_zeiss_master_prime_100mm",
               "arri_signature_prime_58mm_ex1", "arri_signature_prime_58mm_ex2")
MULTI_RESIDUAL = 0.0025  # the "multi" coating's reflectance per glass-air surface (docs/ray-tracing.md)


def axial_transmittance_by_hand(p) -> float:
    """Product over the index steps of 1 - R at normal incidence; a glass-air step of a "multi"
    coated lens reflects min(R, 0.25 %), a cemented (glass-glass) step R uncoated."""
    wl, before, tau = p.wavelength_nm, 1.0, 1.0
    for s in p.surfaces:
        after = float(medium_index(s.medium, wl))
        if after != before:
            r = ((before - after) / (before + after)) ** 2
            glass_air = (before == 1.0) != (after == 1.0)
            if glass_air and p.metadata.coating == "multi":
                r = min(r, MULTI_RESIDUAL)
            tau *= 1.0 - r
        before = after
    return tau


def traced_transmittance(p) -> float:
    h = 1e-3 * p.surfaces[0].semi_diameter
    out = trace_through(p, RayBatch.collimated([0.0], [h], -1.0, wavelength_nm=p.wavelength_nm),
                        fresnel=True, coating=p.metadata.coating, backend="numpy")
    assert out.ok.all()
    return float(out.weight[0])


@pytest.mark.parametrize("slug", CINE_PRIMES)
def test_the_traced_axial_transmittance_is_the_fresnel_product(slug):
    p = load_lens(slug)
    assert p.metadata.coating == "multi"
    assert traced_transmittance(p) == pytest.approx(axial_transmittance_by_hand(p), rel=1e-9)


@pytest.mark.parametrize("slug", CINE_PRIMES)
def test_no_t_stop_is_written_and_maker_data_gives_the_estimate(slug):
    """The file states no T-stop (no maker page reached); its maker_data line says so and gives the
    Fresnel-only estimate, which must be the one worked by hand here, to its printed digits."""
    p = load_lens(slug)
    assert p.metadata.t_stop is None
    n = gaussian(p).f_number
    tau = axial_transmittance_by_hand(p)
    (line,) = [x for x in provenance_of(p).maker_data if x.startswith("T-stop")]
    assert "maker" in line and "not reached" in line and "no absorption" in line
    t_printed = float(re.search(r"Fresnel-only estimate T(\d\.\d\d)", line).group(1))
    tau_printed = float(re.search(r"axial transmittance (0\.\d{3})", line).group(1))
    assert t_printed == pytest.approx(n / math.sqrt(tau), abs=0.005)
    assert tau_printed == pytest.approx(tau, abs=5e-4)
    assert n < t_printed < n * 2 ** (1 / 6)  # faster than a sixth of a stop past the f-number: no absorption


def test_an_uncoated_lens_loses_more_than_a_coated_one():
    """The same prescription uncoated: each glass-air step reflects its full R (4 to 8 % here), so
    the estimate moves well past the coated one (the pbrt double Gauss has no coating given)."""
    p = load_lens("dgauss_50mm")
    assert p.metadata.coating is None
    tau = traced_transmittance(p)
    assert tau == pytest.approx(axial_transmittance_by_hand(p), rel=1e-9)
    assert tau < 0.65  # 12 glass-air surfaces of nd 1.58 to 1.67: about 0.95 each
