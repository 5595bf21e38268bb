"""Matplotlib helpers for the analyses (see :mod:`physcam.figures`): Agg canvases, no pyplot."""

from __future__ import annotations

from ..figures import save_figure, subplots


def figure(width: float = 5.0, height: float = 3.6, ncols: int = 1):
    fig, axes = subplots(1, ncols, figsize=(width, height), squeeze=True)
    return fig, axes


def save(fig, path=None, force: bool = False):
    """Lay out ``fig``; write it to ``path`` and return the path, or return the figure."""
    fig.tight_layout()
    return fig if path is None else save_figure(fig, path, force=force)
