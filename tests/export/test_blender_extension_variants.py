"""The extension's one shader source per lens: each of its four variants, as the add-on writes it into
Blender (``physcam.export.blender_variant``, the zip's ``shader_variant.py``), is the program physcam
wrote for that variant before (``focus_table_shader`` with ``dispersion`` and ``fresnel`` given, the
zip's four shaders per lens until round 11): the same after the C preprocessor, and, without one, the
same lines once the variant's switches are resolved."""

from __future__ import annotations

import shutil
import subprocess

import pytest

from physcam.export.blender_focus import focus_table, focus_table_shader
from physcam.export.blender_variant import variant_source, variant_text_name
from physcam.lens.library import load_lens

VARIANTS = [(d, f) for d in (False, True) for f in (False, True)]
SWITCHES = ("PHYSCAM_DISPERSION", "PHYSCAM_FRESNEL", "PHYSCAM_SP")


@pytest.fixture(scope="module")
def shaders():
    """(the one source, {variant: the reference shader}) of a small focus table (3 states: the
    variants' parts do not depend on the table's size) of the cheapest lens to tabulate, which has
    ghosts (PHYSCAM_SP set by them too). Every bundled lens's four were checked so once (round 11,
    docs/performance.md)."""
    ft = focus_table(load_lens("dgauss_77deg_3_5201mm"), n_focus=3)
    pupil = [40.0, 41.0, 43.0]  # the entrance pupil's distances: any numbers, the same in both
    ref = {v: focus_table_shader(ft, dispersion=v[0], fresnel=v[1], pupil_mm=pupil) for v in VARIANTS}
    return focus_table_shader(ft, dispersion=None, fresnel=None, pupil_mm=pupil), ref


def _cpp(text: str) -> list[str]:
    """The C preprocessor's output (no line markers), its non-blank lines stripped."""
    p = subprocess.run([shutil.which("cpp"), "-P", "-undef", "-nostdinc", "-w", "-"], input=text, text=True,
                       capture_output=True, check=True)
    return [ln.strip() for ln in p.stdout.splitlines() if ln.strip()]


@pytest.mark.skipif(shutil.which("cpp") is None, reason="no C preprocessor (cpp) on this machine")
@pytest.mark.parametrize("variant", VARIANTS)
def test_each_variant_preprocesses_to_the_program_of_that_variant(shaders, variant):
    source, ref = shaders
    got = _cpp(variant_source(source, dispersion=variant[0], fresnel=variant[1]))
    want = _cpp(ref[variant])
    assert len(got) > 200 and got == want
    # the variant's own code is there: the dispersion's coefficients or the fixed indices
    assert any(ln.startswith("float DB[") for ln in got) == variant[0]
    assert any(ln.startswith("float N1[") for ln in got) == (not variant[0])


def _switched(text: str) -> list[str]:
    """``text`` with #ifdef / #ifndef / #else / #endif of :data:`SWITCHES` resolved as the preprocessor
    does (each switch defined where a ``#define`` of it is kept), their ``#define`` lines and the comment
    lines dropped, each line stripped."""
    defined, keep, out = set(), [], []  # keep: per open conditional, (ours, keeping)
    for line in text.splitlines():
        word = line.split()
        on = all(k for _, k in keep)
        if word[:1] in (["#ifdef"], ["#ifndef"]):
            ours = word[1] in SWITCHES
            keep.append((ours, (word[1] in defined) == (word[0] == "#ifdef") if ours else True))
            if ours:
                continue
        elif word[:1] == ["#else"] and keep[-1][0]:
            keep[-1] = (True, not keep[-1][1])
            continue
        elif word[:1] == ["#endif"] and keep.pop()[0]:
            continue
        if not on:
            continue
        if word[:1] == ["#define"] and word[1] in SWITCHES:
            defined.add(word[1])
        elif line.strip() and not line.lstrip().startswith("//"):
            out.append(line.strip())
    assert not keep
    return out


@pytest.mark.parametrize("variant", VARIANTS)
def test_each_variant_is_the_old_shaders_lines_once_its_switches_are_resolved(shaders, variant):
    source, ref = shaders
    got = _switched(variant_source(source, dispersion=variant[0], fresnel=variant[1]))
    assert got == _switched(ref[variant])
    assert not any(s in ln for ln in ref[variant].splitlines() if ln.startswith("#if") for s in SWITCHES)


def test_the_variants_text_names_are_those_the_four_shader_zips_gave():
    """A .blend saved with an earlier extension holds texts of these names: the add-on finds and keeps them."""
    assert [variant_text_name("dgauss_50mm", d, f) for d, f in VARIANTS] == [
        "physcam_dgauss_50mm__d0f0.osl", "physcam_dgauss_50mm__d0f1.osl",
        "physcam_dgauss_50mm__d1f0.osl", "physcam_dgauss_50mm__d1f1.osl"]
