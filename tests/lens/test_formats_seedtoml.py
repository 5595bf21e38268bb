import pytest

from physcam.errors import LensFileError
from physcam.lens.formats import dumps_lens, loads_lens, read_lens

from lens_reference import REFERENCE, SEED_FILES, SEED_INVALID, SEED_VALID

SEED = REFERENCE / "physical-camera-toml"


@pytest.mark.parametrize("path", SEED_VALID, ids=lambda p: p.name)
@pytest.mark.parametrize("via", ["seed-toml", "physcam"])
def test_round_trip(path, via):
    p = read_lens(path)
    assert loads_lens(dumps_lens(p, via), via) == p


def test_all_shared_files_are_accounted_for():
    assert len(SEED_FILES) == 15 and SEED_INVALID <= {f.name for f in SEED_FILES}


@pytest.mark.parametrize("name", sorted(SEED_INVALID))
def test_unbuildable_published_files_are_refused_with_a_line(name):
    with pytest.raises(LensFileError) as exc:
        read_lens(SEED / name)
    assert exc.value.line is not None and exc.value.path.endswith(name)


def test_aperture_is_full_diameter_and_types():
    p = read_lens(SEED / "navarro_anamorphic_2x.toml")
    assert p.surfaces[0].semi_diameter == 60.195 / 2
    assert p.squeeze == 2.0 and p.is_anamorphic
    kinds = [s.kind for s in p.surfaces]
    assert kinds[1] == "flat" and kinds[11] == "stop" and kinds[12] == "cylindrical_x"
    assert kinds.count("cylindrical_y") == 3
    last = p.surfaces[-1]
    assert last.kind == "aspheric" and last.aspheric == (8.75413e-7, -1.46573e-9, 2.5569e-12, -4.86557e-15)
    assert p.surfaces[0].medium.vd == 37.4 and p.surfaces[1].medium.is_air
    # focus.variable surfaces are 0-based (seed 003) and keep the infinity thickness
    assert p.focus.close_distance == 1000.0
    assert [(g.surface, g.thickness_infinity, g.thickness_close) for g in p.focus.gaps] == [
        (3, 14.6763, 1.73), (21, 3.8377, 6.70)]


BASE = """[lens]
name = "t"
[[surface]]
radius = 50.0
thickness = 5.0
ior = 1.5
aperture = 20.0
abbe_v = 60.0
[[surface]]
type = "stop"
radius = 0.0
thickness = 2.0
ior = 1.0
aperture = 18.0
[[surface]]
radius = -50.0
thickness = 40.0
ior = 1.0
aperture = 20.0
"""


@pytest.mark.parametrize(
    "old, new, line, match",
    [
        ("radius = -50.0", "radius = -50.0\nconic = -1.0", 15, "need type"),
        ('type = "stop"', 'type = "toric"', 9, "unknown type"),
        ("aperture = 18.0", "aperture = 'x'", 9, "must be a number"),
        ("abbe_v = 60.0", "abbe_v = 60.0\nradus = 3", 3, "unknown key 'radus'"),
        ("thickness = 2.0", "thickness = nan", 9, "finite"),
        ("aperture = 20.0\nabbe", "aperture = 120.0\nabbe", 3, "exceeds the radius"),
    ],
)
def test_bad_input(old, new, line, match):
    with pytest.raises(LensFileError, match=match) as exc:
        loads_lens(BASE.replace(old, new, 1), "seed-toml", "t.toml")
    assert exc.value.line == line


def test_focus_surface_out_of_range():
    text = BASE + "[focus]\nclose_distance = 500.0\n[[focus.variable]]\nsurface = 3\nthickness_close = 1.0\n"
    with pytest.raises(LensFileError, match="0-based") as exc:
        loads_lens(text, "seed-toml", "t.toml")
    assert exc.value.line == 22  # the [[focus.variable]] header
