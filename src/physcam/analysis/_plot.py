"""Matplotlib helpers for the analyses: Agg backend, imported lazily; PNGs written atomically."""

from __future__ import annotations


def figure(width: float = 5.0, height: float = 3.6, ncols: int = 1):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, ncols, figsize=(width, height), squeeze=True)
    return fig, axes


def save(fig, path=None, force: bool = False):
    """Write ``fig`` as PNG to ``path`` through :func:`physcam.io.atomic_write` (when given); return it."""
    fig.tight_layout()
    if path is not None:
        import io as _io

        import matplotlib.pyplot as plt

        from ..io import atomic_write

        buf = _io.BytesIO()
        fig.savefig(buf, format="png", dpi=130)
        atomic_write(path, buf.getvalue(), force=force)
        plt.close(fig)
    return fig
