import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.errors import LensFileError
from physcam.lens.catalog import find_glass
from physcam.lens.formats import dumps_lens, loads_lens
from physcam.lens.prescription import AIR, Focus, LensMetadata, Medium, Prescription, Surface, VariableGap

finite = st.floats(min_value=-1e3, max_value=1e3, allow_nan=False, allow_infinity=False)


@st.composite
def lenses(draw):
    """Valid lenses: thin elements (|R| >= 40, semi <= 10) separated by generous gaps, one stop."""
    n = draw(st.integers(2, 8))
    stop = draw(st.integers(0, n - 1))
    surfaces = []
    for i in range(n):
        semi = draw(st.floats(1.0, 10.0))
        if i == stop:
            surfaces.append(Surface(0.0, draw(st.floats(6.0, 20.0)), AIR, semi, "stop"))
            continue
        r = draw(st.floats(40.0, 1e4)) * draw(st.sampled_from([-1, 1]))
        kind = draw(st.sampled_from(["spherical", "aspheric", "cylindrical_x", "cylindrical_y", "flat"]))
        medium = draw(st.sampled_from([AIR, Medium(1.5168, 64.17, "N-BK7"),
                                       Medium(draw(st.floats(1.0, 2.0)), draw(st.just(0.0) | st.floats(15.0, 90.0)))]))
        conic, asph = 0.0, ()
        if kind == "aspheric":
            conic = draw(st.floats(-2.0, 0.5))
            # each term at most 0.01 mm at the 10 mm edge, so elements cannot cross
            asph = tuple(draw(st.floats(-1.0, 1.0)) * 1e-2 / 10.0 ** (2 * k + 4) for k in range(draw(st.integers(0, 7))))
        surfaces.append(Surface(0.0 if kind == "flat" else r, draw(st.floats(6.0, 20.0)), medium, semi, kind, conic, asph))
    focus = None
    air = [i for i, s in enumerate(surfaces) if s.medium == AIR]
    if air and draw(st.booleans()):
        i = draw(st.sampled_from(air))
        focus = Focus(draw(st.floats(100.0, 1e4)), (VariableGap(i, surfaces[i].thickness, draw(st.floats(0.0, 20.0))),))
    meta = LensMetadata(name=draw(st.text(min_size=1, max_size=20)), maker=draw(st.none() | st.text(max_size=10)),
                        focal_length=draw(st.none() | st.floats(1.0, 1e3)), notes=draw(st.none() | st.text(max_size=40)))
    extras = tuple(sorted({("iset.microlens", '{"x":[1,2]}'), ("provenance.aliases", '["a","b"]')}))
    p = Prescription(tuple(surfaces), meta, focus, draw(st.sampled_from([1.0, 1.33, 2.0])), extras=extras)
    return p.validate()


@settings(max_examples=60, deadline=None)
@given(lenses())
def test_round_trip_property(p):
    assert loads_lens(dumps_lens(p, "physcam"), "physcam") == p


@settings(max_examples=40, deadline=None)
@given(lenses())
def test_seed_toml_keeps_the_geometry(p):
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        q = loads_lens(dumps_lens(p, "seed-toml"), "seed-toml")
    def strip(s):
        return (s.radius, s.thickness, s.semi_diameter, s.kind, s.conic, s.aspheric, s.medium.nd, s.medium.vd)

    assert [strip(s) for s in q.surfaces] == [strip(s) for s in p.surfaces]
    assert q.focus == p.focus and q.squeeze == p.squeeze


MINIMAL = """format = "physcam-lens/1"
[lens]
name = "glass by name"
[[surface]]
kind = "spherical"
radius = 60.0
thickness = 6.0
semi_diameter = 12.0
medium = { glass = "n-bk7" }
[[surface]]
kind = "stop"
radius = 0.0
thickness = 50.0
semi_diameter = 10.0
medium = "air"
"""


def test_glass_name_from_the_catalogue():
    s = loads_lens(MINIMAL, "physcam").surfaces[0]
    assert (s.medium.nd, s.medium.vd) == (1.5168, 64.17)  # SCHOTT N-BK7 datasheet
    assert find_glass("N-SF11").nd == 1.78472 and find_glass("f2").vd == 36.37


def test_unknown_glass_suggests():
    with pytest.raises(LensFileError, match="N-BK7") as exc:
        loads_lens(MINIMAL.replace("n-bk7", "N-BK8"), "physcam", "g.toml")
    assert exc.value.line == 4


def test_unknown_kind_and_bad_extras():
    with pytest.raises(LensFileError, match="unknown kind"):
        loads_lens(MINIMAL.replace('kind = "spherical"', 'kind = "toric"'), "physcam")
    with pytest.raises(LensFileError, match="JSON"):
        loads_lens(MINIMAL + '[extras]\n"a" = "{nope"\n', "physcam")


_MAKER_FIELDS = '''format = "physcam-lens/1"
[lens]
name = "maker fields"
max_fstop = 2.0
{extra}
[provenance]
source = "a worked example"
licence = "CC0-1.0"
[[surface]]
kind = "spherical"
radius = 50.0
thickness = 5.0
semi_diameter = 10.0
medium = {{ nd = 1.5168, vd = 64.17 }}
[[surface]]
kind = "stop"
radius = 0.0
thickness = 45.0
semi_diameter = 8.0
medium = "air"
'''


def test_maker_close_focus_and_t_stop_round_trip():
    """The maker's minimum object distance (mm from the film) and T-stop are read, kept and written back."""
    p = loads_lens(_MAKER_FIELDS.format(extra="t_stop = 2.1\nminimum_object_distance = 450.0"), "physcam")
    assert p.metadata.minimum_object_distance == 450.0 and p.metadata.t_stop == 2.1
    assert p.metadata.licence == "CC0-1.0" and p.extras == ()
    back = loads_lens(dumps_lens(p, "physcam"), "physcam")
    assert back.metadata == p.metadata
    bare = loads_lens(_MAKER_FIELDS.format(extra=""), "physcam")
    assert bare.metadata.minimum_object_distance is None and bare.metadata.t_stop is None


@pytest.mark.parametrize("extra, words", [
    ("minimum_object_distance = -300.0", "positive distance"),
    ("minimum_object_distance = 0.0", "positive distance"),
    ("t_stop = 1.4", "faster than the lens's f-number"),
])
def test_maker_fields_that_cannot_be_are_refused(extra, words):
    with pytest.raises(LensFileError, match=words):
        loads_lens(_MAKER_FIELDS.format(extra=extra), "physcam")


RECORD = '''format = "physcam-lens/1"
[lens]
name = "record"
[provenance]
source = "US 2,673,491 (A. W. Tronnier), example 1"
licence = "CC0-1.0"
transcribed = "2026-11-28"
primary_source_checked = true
checks = ["EFL 100.0 mm stated, 100.02 computed", "f/2 stated, f/2.01 computed"]
assumptions = ["stop: midway in the central air space, as the patent's figure shows"]
{extra}
[[surface]]
kind = "stop"
radius = 0.0
thickness = 10.0
semi_diameter = 5.0
medium = "air"
'''


def test_provenance_record_is_read_written_and_read_back():
    from physcam.lens.provenance import provenance_of

    p = loads_lens(RECORD.format(extra=""), "physcam")
    prov = provenance_of(p)
    assert (prov.source, prov.licence, prov.transcribed) == ("US 2,673,491 (A. W. Tronnier), example 1", "CC0-1.0",
                                                           "2026-11-28")
    assert prov.primary_source_checked is True and prov.checks == ("EFL 100.0 mm stated, 100.02 computed",
                                                                   "f/2 stated, f/2.01 computed")
    text = dumps_lens(p, "physcam")
    assert loads_lens(text, "physcam") == p
    # written in the record's order, a list of several one item a line
    keys = [line.split(" =")[0] for line in text[text.index("[provenance]"):text.index("[[surface]]")].splitlines()
            if " = " in line]
    assert keys == ["source", "licence", "transcribed", "primary_source_checked", "checks", "assumptions"]
    assert 'checks = [\n    "EFL 100.0 mm stated, 100.02 computed",\n' in text


@pytest.mark.parametrize("extra, words", [
    ('checked = "28 Nov 2026"', "checked must be a date as YYYY-MM-DD"),
    ('checked = "2026-02-30"', "checked must be a date"),
    ('primary_source_checked = "yes"', "must be true or false"),
    ('checks = "one check"', "checks must be a list of strings"),
    ('maker_data = [1, 2]', "maker_data must be a list of strings"),
    ('source_url = 3', "source_url must be a string"),
])
def test_a_provenance_record_of_the_wrong_kind_is_refused(extra, words):
    key = extra.split(" =")[0]  # the record's own line of that key gives way to the wrong one
    text = "\n".join(line for line in RECORD.splitlines() if not line.startswith(key + " =")) + "\n"
    text = text.replace("{extra}", extra)
    with pytest.raises(LensFileError, match=words):
        loads_lens(text, "physcam")


@pytest.mark.parametrize("line", ['format="physcam-lens/1"', "format = 'physcam-lens/1'", '  format  =  "physcam-lens/1"'])
def test_the_format_line_is_read_however_toml_spaces_or_quotes_it(tmp_path, line):
    """A lens vendor's `format="physcam-lens/1"` (valid TOML) was read as the seed TOML and refused as
    "unknown key 'format'" (round 8). Oracle: the file written with the documented spacing."""
    from physcam.lens.formats import read_lens

    f = tmp_path / "mine.toml"
    f.write_text(MINIMAL.replace('format = "physcam-lens/1"', line))
    assert read_lens(f) == loads_lens(MINIMAL, "physcam")


def test_a_physcam_toml_without_its_format_line_is_told_to_add_it(tmp_path):
    """Without the line the file was read as the seed TOML: "top level: unknown key 'provenance' ..."."""
    from physcam.lens.formats import read_lens

    f = tmp_path / "mine.toml"
    f.write_text(MINIMAL.replace('format = "physcam-lens/1"\n', ""))
    with pytest.raises(LensFileError, match=r'starts with the line format = "physcam-lens/1"') as err:
        read_lens(f)
    assert err.value.line == 1
