"""bokeh_image reports progress per chunk, ending at the total."""

from physcam.analysis.defocus.bokeh import bokeh_image
from physcam.lens.library import load_lens


def test_progress_reaches_total():
    calls = []
    bokeh_image(load_lens("dgauss_50mm"), 1000.0, rays=5000, chunk=2000, pixels=16,
                progress=lambda done, total: calls.append((done, total)))
    assert calls == [(2000, 5000), (4000, 5000), (5000, 5000)]
