"""``characterize`` on a farm: the grid's points as a farm's frames, each task a run of points.

A characterization grid (:mod:`physcam.characterize.grid`) has, per lens, focus marks and f-stops;
its **points** are numbered 1, 2, ... lens by lens, then focus mark by focus mark, then f-stop by
f-stop (:data:`GRID_AXES`; a zoom axis would go between the lens and the focus). A farm task takes
a run of points ``first..last`` and makes every cell of the grid that belongs to them
(:func:`point_of`: a PSF or illumination cell to its own point, a distortion cell to its focus mark's
point at the first f-stop, the lens cell to the lens's first point), with the very function Dask runs
for a task (:func:`physcam.characterize.cells.run_cells`, in the same groups,
:func:`physcam.characterize.run.task_groups`). So the result files are those of ``physcam
characterize`` run directly; a cell already in the index is skipped (resumable: a killed task's
rerun makes only what is missing, each cell written atomically under its lock). The last step adds
the USD variant of each complete lens (:func:`finish_lenses`,
:func:`physcam.characterize.library.lens_usd_update`), under the job's one run id.
"""

from __future__ import annotations

from pathlib import Path

from ..errors import InputError, OpticsError, require_type

__all__ = ["GRID_AXES", "grid_points", "point_of", "run_points", "finish_lenses"]

#: The axes a grid point has, outermost first
GRID_AXES = ("lens", "focus_mm", "fstop")


def _grid(grid):
    from ..characterize.grid import Grid

    return require_type("grid", grid, Grid, "physcam.characterize.Grid(focus_mm=..., fstops=...)")


def grid_points(lenses, grid) -> list[tuple]:
    """Every point of the grid, numbered from 1 in this order: (lens slug, focus mark mm, f-stop)."""
    require_type("lenses", lenses, (dict, list, tuple), "the lens slugs in order")
    _grid(grid)
    for slug in lenses:
        require_type("lens slug", slug, str, "the lens's folder name")
    return [(slug, m, n) for slug in lenses for m in grid.focus_mm for n in grid.fstops]


def point_of(cell, grid) -> tuple:
    """The grid point a cell belongs to: its own lens, focus and f-stop, the grid's first where it has none."""
    from ..characterize.grid import Cell

    require_type("cell", cell, Cell, "physcam.characterize.build_cells")
    _grid(grid)
    return (cell.lens, grid.focus_mm[0] if cell.focus_mm is None else cell.focus_mm,
            grid.fstops[0] if cell.fstop is None else cell.fstop)


def _plan(lenses, grid):
    from .. import __version__

    _grid(grid)
    from ..characterize.run import plan_cells

    return plan_cells(lenses, grid.checked(), __version__), __version__


def run_points(lenses: dict, grid, output, run_id: str, first: int, last: int) -> dict:
    """Make the cells of grid points ``first..last`` (1-based, inclusive) under the library folder ``output``.

    Returns ``{"points": [first, last], "computed", "present", "failed": [{lens, kind, cell, error}]}``."""
    from ..characterize.cells import run_cells
    from ..characterize.run import task_groups

    require_type("run id", run_id, str, "run_YYYYmmddTHHMMSSZ_xxxxxx")
    require_type("output", output, (str, Path), "the library folder")
    for name, v in (("first point", first), ("last point", last)):
        if isinstance(v, bool) or not isinstance(v, int):
            raise InputError(f"the {name} is a whole number, got {v!r}")
    plan, version = _plan(lenses, grid)
    points = grid_points(list(plan), grid)
    if not 1 <= first <= last <= len(points):
        raise InputError(f"the grid has points 1-{len(points)}, the task asks for {first}-{last}")
    chosen = set(points[first - 1:last])
    cells = [c for _, _, cs in plan.values() for c in cs if point_of(c, grid) in chosen]
    root = str(Path(output).resolve())
    out = {"points": [first, last], "computed": 0, "present": 0, "failed": []}
    for group in task_groups(cells):
        toml, digest, _ = plan[group[0].lens]
        for res in run_cells(toml, digest, group, grid.checked(), root, run_id, version):
            if res["status"] == "failed":
                c = res["cell"]
                out["failed"].append({"lens": c.lens, "kind": c.kind, "cell": c.stem, "error": res["error"]})
            else:
                out[res["status"]] += 1
    return out


def finish_lenses(lenses: dict, grid, output, run_id: str) -> list[dict]:
    """Add the run's characterization variant to each lens's USD file (as ``physcam characterize`` does
    once its grid is complete); an :class:`OpticsError` naming the cells missing when a lens's grid is not."""
    from ..characterize.library import lens_usd_update

    require_type("run id", run_id, str, "run_YYYYmmddTHHMMSSZ_xxxxxx")
    require_type("output", output, (str, Path), "the library folder")
    plan, _ = _plan(lenses, grid)
    out = Path(output)
    missing = {slug: [c for c in cells if not (out / c.index_name).is_file()] for slug, (_, _, cells) in plan.items()}
    gaps = {slug: cs for slug, cs in missing.items() if cs}
    if gaps:
        slug, cs = next(iter(gaps.items()))
        raise OpticsError(f"{sum(len(v) for v in gaps.values())} cells are not made (first: {slug} {cs[0].kind} "
                          f"{cs[0].stem}): their tasks failed or have not run; the USD variant waits for them")
    done = []
    for slug, rx in plan.items():
        res = lens_usd_update(lenses[slug], slug, rx[2], grid.checked(), out, run_id)
        if res is not None:
            done.append(res)
    return done
