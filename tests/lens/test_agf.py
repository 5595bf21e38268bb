"""Hostile and odd Zemax .agf glass catalogues (issue 40 item 14): devices, FIFOs, NaN and inf,
encodings, truncated Sellmeier lines, formula 2.7, duplicated names, a glass used outside its
stated range. Every refusal is one line naming the file and the line; nothing hangs or grows.

The glass in the catalogues below is SCHOTT N-BK7 (Sellmeier coefficients from SCHOTT's data
sheet): nF = 1.52238 (the sheet's printed index) is the number a catalogue read right gives."""

import os
import subprocess
import sys
import warnings
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from physcam.errors import LensFileError, PhysCamWarning
from physcam.lens.agf import loads_agf, read_agf
from physcam.optics.glass import LINE_F_NM

DATA = Path(__file__).resolve().parents[1] / "data"
BK7_CD = "CD 1.03961212 0.00600069867 0.231792344 0.0200179144 1.01046945 103.560653 0 0 0 0"
AGF = "\r\n".join(["CC test catalogue", "NM MYBK7 2 517642 1.5168 64.17 0 1 0", "GC Schott's N-BK7 under another name",
                   "ED 7.1 8.3 2.51 -0.0009 0", BK7_CD, "LD 0.3 2.5",
                   "NM MYCON 5 0 1.5 50 0 0 0", "CD 1.48 0.01 0.0002 0 0 0 0 0 0 0", "LD 0.35 1.1", ""])


def _one_line_error(text, name="T.agf", match=None):
    with pytest.raises(LensFileError, match=match) as exc:
        loads_agf(text, "T", name)
    assert "\n" not in str(exc.value)
    return exc.value


def test_the_reference_catalogue_reads():
    g = loads_agf(AGF, "T")
    assert float(g["MYBK7"].index(LINE_F_NM)) == pytest.approx(1.52238, abs=6e-6)  # SCHOTT's printed nF
    assert g["MYBK7"].range_nm == (300.0, 2500.0)


@pytest.mark.parametrize("bad, line", [
    ("NM MYBK7 2 517642 nan 64.17 0 1 0", 2), ("NM MYBK7 2 517642 1.5168 inf 0 1 0", 2),
    (BK7_CD.replace("103.560653", "inf"), 5), (BK7_CD.replace("0.231792344", "NaN"), 5),
    (BK7_CD.replace("103.560653", "1e999"), 5), ("LD nan 2.5", 6), ("LD 0.3 -inf", 6),
    (BK7_CD.replace("103.560653", "1_03.5"), 5), (BK7_CD.replace("103.560653", "0x1p3"), 5),
    ("NM MYBK7 nan 517642 1.5168 64.17 0 1 0", 2), ("NM MYBK7 inf 517642 1.5168 64.17 0 1 0", 2),
])
def test_nan_inf_and_non_decimal_numbers_are_one_line_with_file_and_line(bad, line):
    lines = AGF.split("\r\n")
    key = bad.split()[0]
    i = next(k for k, text in enumerate(lines) if text.startswith(key))
    lines[i] = bad
    err = _one_line_error("\r\n".join(lines))
    assert (err.path, err.line) == ("T.agf", line), str(err)


def test_formula_2_7_is_not_read_as_2():
    err = _one_line_error(AGF.replace("NM MYBK7 2 ", "NM MYBK7 2.7 "), match="formula '2.7' is not one of Zemax's")
    assert err.line == 2
    _one_line_error(AGF.replace("NM MYBK7 2 ", "NM MYBK7 14 "), match="formula '14'")
    assert loads_agf(AGF.replace("NM MYBK7 2 ", "NM MYBK7 2.0 "), "T")["MYBK7"].formula == 2  # a whole number


def test_a_truncated_sellmeier_line_is_an_error():
    cut = AGF.replace(BK7_CD, "CD 1.03961212 0.00600069867 0.231792344 0.0200179144")  # K3, L3 lost
    err = _one_line_error(cut, match=r"Sellmeier 1 formula \(Zemax 2\) uses 6 coefficients, the CD line gives 4")
    assert err.line == 5
    _one_line_error(AGF.replace(BK7_CD, "CD"), match="gives 0")
    _one_line_error(AGF.replace("LD 0.3 2.5", BK7_CD), match="second CD line")


def test_a_wrapped_cd_line_continues_on_the_next_line():
    """Nikon's own catalogue wraps its CD lines (bare numbers on the next lines); they are one line."""
    head, tail = BK7_CD.split(" 1.01046945 ")
    wrapped = AGF.replace(BK7_CD, head + "\r\n1.01046945 " + tail)
    assert loads_agf(wrapped, "T")["MYBK7"].coefficients == loads_agf(AGF, "T")["MYBK7"].coefficients


def test_a_duplicated_name_is_one_warning_naming_both_lines():
    twice = AGF + "NM mybk7 2 0 1.6 40 0 0 0\r\n" + BK7_CD + "\r\n"
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        g = loads_agf(twice, "T", "T.agf")
    assert [str(w.message) for w in seen] == [
        "T.agf: glass defined twice: mybk7 on lines 2 and 10; the first of each is used"]
    assert g["MYBK7"].nd == 1.5168  # the first


def test_entries_that_are_no_usable_glass_are_left_out_with_one_warning():
    """Zemax's own MISC has VACUUM (nd 0.999728) and INFRARED has AMTIR3 (no index at the d line):
    the rest of the catalogue is read, and one warning names what was left out."""
    extra = ("NM VAC 2 1 0.999728 89.195538 0 0 0\r\n" + BK7_CD.replace("1.03961212", "-0.99") + "\r\n"
             "NM IRONLY 3 0 1 0 0 0 0\r\nCD 2.61445159 0.149135 -0.287509 -9.57e-05 -5.1e-07 9.89e-10 0 0 0 0\r\n")
    with pytest.warns(PhysCamWarning, match=r"2 entries left out.*VAC \(line 10: no index at 587.56 nm\), IRONLY"):
        g = loads_agf(AGF + extra, "T", "T.agf")
    assert sorted(g) == ["MYBK7", "MYCON"]
    _one_line_error("CC nothing here\r\n", match="no glass")


ENCODINGS = {
    "utf-16 with BOM": lambda t: t.encode("utf-16"),
    "utf-16-le without BOM": lambda t: t.encode("utf-16-le"),
    "utf-16-be without BOM": lambda t: t.encode("utf-16-be"),
    "utf-8 with BOM": lambda t: t.encode("utf-8-sig"),
    "latin-1": lambda t: t.encode("latin-1"),
    "cp1252 undefined byte": lambda t: t.encode("latin-1").replace(b"Schott", b"Sch\x81tt"),
    "mixed line ends": lambda t: t.replace("\r\n", "\n", 3).replace("\r\n", "\r", 2).encode("ascii", "replace"),
}


@pytest.mark.parametrize("encoding", sorted(ENCODINGS))
def test_odd_encodings_read_the_same_glasses_and_lines(encoding, tmp_path):
    text = AGF.replace("GC Schott's", "GC Schott\u00e9's")  # a non-ASCII comment, as makers write
    f = tmp_path / "ENC.agf"
    f.write_bytes(ENCODINGS[encoding](text))
    name, g = read_agf(f)
    assert name == "ENC" and sorted(g) == ["MYBK7", "MYCON"]
    assert float(g["MYBK7"].index(LINE_F_NM)) == pytest.approx(1.52238, abs=6e-6)
    f.write_bytes(ENCODINGS[encoding](text.replace("LD 0.35 1.1", "LD 0.35 nan")))  # line 9, whatever the ends
    with pytest.raises(LensFileError) as exc:
        read_agf(f)
    assert exc.value.line == 9 and str(f) in str(exc.value)


def test_binary_and_broken_utf16_are_one_line(tmp_path):
    f = tmp_path / "B.agf"
    f.write_bytes(b"\xff\xfe" + "NM X 2 0 1.5 60 0 0 0\n".encode("utf-16-le") + b"\x00")  # an odd byte out
    with pytest.raises(LensFileError, match="not valid UTF-16"):
        read_agf(f)
    f.write_bytes(b"CC " + b"x" * 500 + b"\nNM X 2 0 1.5 60\x00 0 0 0\n")  # a NUL past the UTF-16 sniff
    with pytest.raises(LensFileError, match="NUL bytes"):
        read_agf(f)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs (POSIX)")
def test_devices_fifos_and_folders_are_refused_before_reading(tmp_path):
    fifo = tmp_path / "PIPE.agf"
    os.mkfifo(fifo)
    for path, what in [(fifo, r"a FIFO \(named pipe\)"), ("/dev/zero", "a character device"), (tmp_path, "a folder")]:
        if not os.path.exists(path):
            continue
        with pytest.raises(LensFileError, match=f"glass catalogue is {what}, not a regular file") as exc:
            read_agf(path)
        assert "\n" not in str(exc.value)


def test_a_huge_catalogue_is_refused_from_its_size(tmp_path, monkeypatch):
    import physcam.lens.agf as agf

    f = tmp_path / "BIG.agf"
    f.write_text(AGF * 200)
    monkeypatch.setattr(agf, "MAX_AGF_BYTES", 4096)
    with pytest.raises(LensFileError, match="over 4096 bytes is refused"):
        read_agf(f)


def _cli(argv, env_extra, timeout=60):
    """`physcam ARGV` in its own process (a FIFO read by old code would block this test for ever),
    its address space capped at 3 GB so that an unbounded read fails fast rather than swapping."""

    def cap():
        import resource

        resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))

    env = dict(os.environ, **env_extra)
    return subprocess.run([sys.executable, "-m", "physcam", *argv], capture_output=True, text=True, env=env,
                          timeout=timeout, preexec_fn=cap if sys.platform.startswith("linux") else None)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="needs /dev/zero and FIFOs")
def test_cli_refuses_dev_zero_and_a_fifo_in_one_line_also_from_the_config(tmp_path):
    fifo = tmp_path / "PIPE.agf"
    os.mkfifo(fifo)
    lens = ["lens", "show", "--lens", "dgauss_50mm"]
    r = _cli(lens + ["--glass-catalog", "/dev/zero"], {"PHYSCAM_CONFIG": ""})
    assert r.returncode == 2 and r.stderr.strip().count("\n") == 0, r.stderr[-500:]
    assert "/dev/zero: glass catalogue is a character device, not a regular file" in r.stderr
    cfg = tmp_path / "config.toml"
    cfg.write_text(f'glass_catalogs = ["{fifo}"]\n')
    r = _cli(lens, {"PHYSCAM_CONFIG": str(cfg)})
    assert r.returncode == 2 and r.stderr.strip().count("\n") == 0, r.stderr[-500:]
    assert f"the physcam config {cfg}: glass_catalogs: {fifo} is a FIFO, not a regular file" in r.stderr


def test_a_glass_used_outside_its_stated_range_warns(tmp_path):
    """The rule (docs/lens-formats.md): a catalogue glass whose stated range does not hold the lens
    file's design wavelength is one warning naming the glass, its range and the wavelength, as
    OpticStudio warns; the lens loads (its formula is extrapolated there)."""
    from physcam.lens.catalog import use_catalog_files
    from physcam.lens.formats import loads_lens

    agf = tmp_path / "NARROW.agf"
    agf.write_text(AGF.replace("LD 0.3 2.5", "LD 0.40 0.41"))
    text = (DATA / "zemax" / "asphere_780nm.zmx").read_text().replace("S-LAH64", "MYBK7")
    use_catalog_files([agf])
    try:
        with warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("always")
            lens = loads_lens(text, "zemax", "a.zmx")
        assert [str(w.message) for w in seen] == [
            "a.zmx: the design wavelength 780 nm lies outside the stated range of MYBK7 (NARROW) states 400-410 nm: "
            "its formula is extrapolated there"]
        assert lens.wavelength_nm == 780.0
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # in range: nothing said
            loads_lens(text.replace("WAVM 1 0.78", "WAVM 1 0.405"), "zemax", "a.zmx")
    finally:
        use_catalog_files([])


# --- fuzz: whatever the bytes, LensFileError or a catalogue of finite, usable glasses ------------
FUZZ = settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
TOKENS = st.sampled_from(["nan", "inf", "-inf", "1e999", "2.7", "0", "-1", "", "NM", "CD", "LD", "\x00", "\r",
                          "9" * 400, "1e-320", "x", "13", "14", "NM A 2", "\ufeff"])


def _check(text):
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PhysCamWarning)
            glasses = loads_agf(text, "F", "fuzz.agf")
    except LensFileError as exc:
        assert "\n" not in str(exc)
        return
    for g in glasses.values():
        n = float(g.index(587.5618))
        assert n == n and 1.0 < n < 10 and all(c == c and abs(c) != float("inf") for c in g.coefficients)


@FUZZ
@given(data=st.data())
def test_mutated_catalogues_never_traceback(data):
    lines = AGF.split("\r\n")
    for _ in range(data.draw(st.integers(1, 4))):
        i = data.draw(st.integers(0, len(lines) - 1))
        tok = lines[i].split(" ")
        j = data.draw(st.integers(0, max(0, len(tok) - 1)))
        tok[j] = data.draw(TOKENS)
        lines[i] = " ".join(tok)
    _check("\r\n".join(lines))


@FUZZ
@given(data=st.binary(max_size=300))
def test_random_bytes_never_traceback(data, tmp_path_factory):
    f = tmp_path_factory.mktemp("fz") / "R.agf"
    f.write_bytes(data)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PhysCamWarning)
            read_agf(f)
    except LensFileError as exc:
        assert "\n" not in str(exc)
