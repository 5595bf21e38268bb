"""Fuzz: whatever the bytes, a reader returns a valid lens or raises LensFileError, nothing else."""

import warnings

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from physcam.errors import LensFileError
from physcam.lens.formats import FORMATS, dumps_lens, loads_lens
from physcam.lens.formats._common import decode
from physcam.lens.library import load_lens

SEEDS = {}
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    for fmt, lens in [("physcam", "canon_rf_85mm_f1_2"), ("seed-toml", "navarro_anamorphic_2x"),
                      ("pbrt", "dgauss_50mm"), ("iset", "dgauss_77deg_3_5201mm"), ("zemax", "zeiss_planar_80mm_f2_8")]:
        SEEDS[fmt] = dumps_lens(load_lens(lens), fmt)

FUZZ = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def _read(data: bytes, fmt: str):
    try:
        p = loads_lens(decode(data, "fuzz"), fmt, "fuzz")
    except LensFileError:
        return
    p.validate()  # anything returned is a valid lens


@pytest.mark.parametrize("fmt", sorted(FORMATS))
@FUZZ
@given(data=st.binary(max_size=400))
def test_random_bytes(fmt, data):
    _read(data, fmt)


@pytest.mark.parametrize("fmt", sorted(FORMATS))
@FUZZ
@given(text=st.text(alphabet=st.sampled_from(list("0123456789.-+eE \t\n#[]{}\"=,:abcdnrsu_")), max_size=300))
def test_random_text(fmt, text):
    _read(text.encode(), fmt)


tokens = st.sampled_from(["0", "-0", "nan", "inf", "1e999", "1e308", "-1e-320", "x", "", "\"", "[", "{", "9" * 50,
                          "-5", "3.5", "1e5", "true", "STOP", "TYPE", "SURF 9"])


@pytest.mark.parametrize("fmt", sorted(FORMATS))
@FUZZ
@given(data=st.data())
def test_mutated_valid_files(fmt, data):
    text = SEEDS[fmt]
    for _ in range(data.draw(st.integers(1, 4))):
        op = data.draw(st.sampled_from(["replace", "truncate", "delete_line", "duplicate_line"]))
        lines = text.splitlines(keepends=True)
        if op == "truncate":
            text = text[: data.draw(st.integers(0, len(text)))]
        elif op == "delete_line" and lines:
            i = data.draw(st.integers(0, len(lines) - 1))
            text = "".join(lines[:i] + lines[i + 1:])
        elif op == "duplicate_line" and lines:
            i = data.draw(st.integers(0, len(lines) - 1))
            text = "".join(lines[: i + 1] + lines[i:])
        else:
            import re

            nums = list(re.finditer(r"-?\d+\.?\d*(e-?\d+)?|[A-Za-z_]+", text))
            if nums:
                m = data.draw(st.sampled_from(nums))
                text = text[: m.start()] + data.draw(tokens) + text[m.end():]
    _read(text.encode(), fmt)


def test_huge_file_refused(tmp_path):
    from physcam.lens.formats import read_lens

    big = tmp_path / "big.dat"
    big.write_bytes(b"# x\n" * (3 * 1024 * 1024))
    with pytest.raises(LensFileError, match="refused"):
        read_lens(big)
    with pytest.raises(LensFileError, match="more than 500"):
        loads_lens("10 1 1.5 5\n" * 501, "pbrt")
