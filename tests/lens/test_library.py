import pytest

from physcam.errors import InputError
from physcam.lens.formats import dumps_lens, loads_lens, read_lens
from physcam.lens.formats._common import extra
from physcam.lens.library import find_lens, list_lenses, load_lens

from lens_reference import ISET_FILES, PBRT_FILES, REFERENCE, SEED_FILES, SEED_INVALID

ALL_REFERENCE = PBRT_FILES + ISET_FILES + SEED_FILES


#: The Blender extension's copy of the pbrt double Gauss (the same prescription with Abbe numbers of its
#: own): dropped from the library in issue 44, its name an alias of dgauss_50mm.
DUPLICATE = "double_gauss_50mm_f2.toml"


def test_every_reference_file_is_bundled_once():
    recs = list_lenses()
    originals = sorted(r.original_file for r in recs)
    assert originals == sorted(f"{f.parent.name}/{f.name}" for f in ALL_REFERENCE if f.name != DUPLICATE)
    assert len({r.slug for r in recs}) == len(recs) == 18
    assert find_lens(DUPLICATE).slug == find_lens("double_gauss_50mm_f2").slug == "dgauss_50mm"


@pytest.mark.parametrize("rec", list_lenses(), ids=lambda r: r.slug)
def test_bundled_lens_is_valid_and_round_trips(rec):
    p = load_lens(rec.slug)
    p.validate()
    assert loads_lens(dumps_lens(p, "physcam"), "physcam") == p
    assert rec.source and rec.original_format in ("pbrt", "iset", "seed-toml")


def _numbers(p):
    """Each surface's geometry, nd and Vd: what a transcription is (a glass name added later is not)."""
    return [(s.kind, s.radius, s.thickness, s.semi_diameter, s.conic, s.aspheric, s.medium.nd, s.medium.vd)
            for s in p.surfaces]


@pytest.mark.parametrize("path", [f for f in ALL_REFERENCE if f.name not in SEED_INVALID], ids=lambda p: p.name)
def test_uncorrected_lenses_equal_their_original(path):
    rec = find_lens(path.name)
    assert not rec.corrected or path.suffix == ".json"  # the ISET copy corrects only its name
    bundled, original = _numbers(load_lens(rec.slug)), _numbers(read_lens(path))
    if path.name == DUPLICATE:  # the same radii, gaps, nd and apertures; the Abbe numbers are the copy's own
        bundled, original = [b[:-1] for b in bundled], [o[:-1] for o in original]
    assert bundled == original


@pytest.mark.parametrize("name", sorted(SEED_INVALID))
def test_corrected_lenses_say_what_and_why(name):
    rec = find_lens(name)
    assert rec.corrected
    notes = extra(load_lens(rec.slug), "provenance.corrections")
    assert notes and all(len(n) > 60 for n in notes)


def test_halved_apertures_match_the_published_surfaces():
    original = (REFERENCE / "physical-camera-toml" / "canon_rf_85mm_f1_2.toml").read_text()
    assert "aperture = 140.4" in original
    assert load_lens("canon_rf_85mm_f1_2").surfaces[0].semi_diameter == 140.4 / 4


def test_names_aliases_and_paths():
    assert find_lens("dgauss.50mm").slug == "dgauss_50mm"
    assert find_lens("Tessar 50mm f/2.8").slug == "tessar_50mm_f2_8"
    assert find_lens("dgauss.22deg.3.0mm").slug == "dgauss_77deg_3_5201mm"  # the ISET file's own name
    p = load_lens(REFERENCE / "pbrt-dat" / "telephoto.250mm.dat")
    assert p == read_lens(REFERENCE / "pbrt-dat" / "telephoto.250mm.dat")
    assert load_lens("navarro anamorphic 2x").is_anamorphic


def test_unknown_name_suggests_the_closest():
    with pytest.raises(InputError, match="did you mean .*tessar_50mm_f2_8"):
        load_lens("tesar 50")
    with pytest.raises(InputError, match="no such lens file"):
        load_lens("missing/lens.dat")


def test_a_slug_loads_the_lens_the_index_finds():
    # load_lens reads a bare slug's file directly (fast path): that must be the very lens the name
    # lookup gives, so no slug may also be another lens's name or alias
    from physcam.lens.library import _key

    recs = list_lenses()
    for rec in recs:
        assert find_lens(rec.slug).slug == rec.slug
        assert load_lens(rec.slug) is load_lens(rec.name)
        for other in recs:
            if other.slug != rec.slug:
                assert _key(rec.slug) not in {_key(other.name), *map(_key, other.aliases)}
