"""A figure's file name is checked as the command line is read (round 22).

Every command that draws a figure to ``-o``/``--plot`` writes it through ``physcam.figures.save_figure``, which
knows .png, .svg and .pdf. The name was checked only there, after the command's work: `ghosts -o x.xyz` refused
after 2.8 s, a large `mtf` or `compare` after their seconds. The commands' figure options now read the name with
``physcam.cli._common.figure_file``. The proof that nothing is done first: each command is given a lens that does
not exist, and the refusal names the file, not the lens (the lens is the command's first work)."""

from __future__ import annotations

import pytest

from physcam.cli import main
from physcam.errors import ExportError, PhysCamError
from physcam.figures import figure_format

NO_LENS = "no_such_lens_anywhere"
COMMANDS = [
    ["spot", "--lens", NO_LENS, "-o"],
    ["bokeh", "--lens", NO_LENS, "-o"],
    ["mtf", "--lens", NO_LENS, "-o"],
    ["psf", "--lens", NO_LENS, "-o"],
    ["ghosts", "--lens", NO_LENS, "-o"],
    ["illumination", "--lens", NO_LENS, "-o"],
    ["distortion", "--lens", NO_LENS, "-o"],
    ["colour", "--lens", NO_LENS, "-o"],
    ["compare", "--lens", NO_LENS, "--lens", NO_LENS, "-o"],
    ["lens", "diagram", "--lens", NO_LENS, "-o"],
    ["lens", "card", "--lens", NO_LENS, "-o"],
    ["lens", "breathing", "--lens", NO_LENS, "-o"],
    ["lens", "zoom", "--lens", NO_LENS, "-o"],
    ["microlens", "render", "--lens", NO_LENS, "-o"],
    ["dof-table", "--focal", "50", "-o"],
    ["report", "--focal", "50", "--fstop", "2.8", "--focus", "3m", "--plot"],
]


@pytest.mark.parametrize("argv", COMMANDS, ids=lambda a: " ".join(a[:2]))
def test_a_figure_name_without_a_figure_format_is_refused_before_any_work(argv, tmp_path, capsys):
    target = tmp_path / "chart.xyz"
    assert main([*argv, str(target)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].endswith("cannot save a figure as 'chart.xyz': use a .png, .svg or .pdf file name"), err
    assert not any(NO_LENS in line for line in err)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name, fmt", [("a.png", "png"), ("A.PNG", "png"), ("card.Pdf", "pdf"), ("x.tar.svg", "svg"),
                                        ("dir.png/chart.svg", "svg")])
def test_the_format_is_the_names_extension(name, fmt):
    assert figure_format(name) == fmt


@pytest.mark.parametrize("name", ["chart", "chart.jpg", "chart.png.bak", "chart.", "png"])
def test_other_names_are_refused(name):
    with pytest.raises(ExportError, match="use a .png, .svg or .pdf file name") as info:
        figure_format(name)
    assert isinstance(info.value, PhysCamError)
