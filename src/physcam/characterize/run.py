"""Run a characterization job on Dask: validate, plan, skip what is done, compute the rest, update USD.

:func:`characterize` is the whole job (``physcam characterize`` calls it):

1. **Validate first**, before any cluster starts: the grid (:meth:`Grid.checked`), every lens
   (each focus mark reachable, each f-stop no faster than the lens), the grid's size (at most
   :data:`~physcam.characterize.grid.MAX_CELLS` cells and :data:`~physcam.characterize.grid.MAX_RAYS`
   traced rays unless ``force_large``), the scheduler address's form and the output folder
   (created, and a file written and removed in it).
2. **Plan**: the cells of every lens (:func:`~physcam.characterize.grid.build_cells`); a cell whose
   row is in the index (same input hash: the hash is in the file name) is skipped. ``limit``
   computes at most that many of the rest (a run in parts; the next run resumes).
3. **Compute** the cells as Dask tasks (:func:`~physcam.characterize.cells.run_cells`; one task per
   ST-map or PSF cell, one per lens for its light cells, :func:`task_groups`,
   ``retries`` for a task whose worker raised, and Dask's own rescheduling when a worker dies),
   on a ``LocalCluster`` of ``workers`` single-threaded worker processes (default: one per core;
   numba in each worker runs one thread, so the workers do not fight for the cores) or, with
   ``scheduler="tcp://HOST:PORT"``, on an existing cluster. The dashboard address is reported.
4. **USD**: for every lens whose grid is complete, the lens's USD file ``LENS/LENS.usda`` gains a
   ``characterization`` variant named by the run id holding the measured data, and ``current``
   becomes a copy of it (:func:`physcam.usd.kit.add_characterization`), unless a variant of the
   same grid (the same cells' input hashes) is there already: nothing new was recorded.
"""

from __future__ import annotations

import os
import re
import secrets
import time
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import ExportError, InputError, OpticsError, PhysCamError, WrongTypeError, require_type
from ..lens.prescription import Prescription
from .grid import HARD_MAX_CELLS, MAX_CELLS, MAX_RAYS, Grid, build_cells, lens_hash, lens_slug

__all__ = ["characterize", "CharacterizeSummary", "check_scheduler_address", "read_index", "DEFAULT_CONNECT_TIMEOUT_S",
           "plan_cells", "new_run_id", "load_lenses"]

DEFAULT_CONNECT_TIMEOUT_S = 10.0
_ADDRESS = re.compile(r"^(tcp|tls|ws|wss)://(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9._-]+):(\d{1,5})$")


@dataclass
class CharacterizeSummary:
    """What a run did. Times in seconds; ``overhead`` is 1 - compute / (workers x wall) over the compute phase."""

    run_id: str
    output: str
    lenses: list[str]
    cells: int
    computed: int = 0
    skipped: int = 0  # done before this run started (row in the index)
    present: int = 0  # done by another run (or a killed attempt) while this one ran
    failed: list[dict] = field(default_factory=list)
    not_run: int = 0  # left for a later run by ``limit``
    workers: int = 0
    scheduler: str | None = None
    dashboard: str | None = None
    cluster_start_s: float = 0.0
    wall_s: float = 0.0
    compute_s: float = 0.0
    usd: list[dict] = field(default_factory=list)
    dry_run: bool = False
    grid: dict = field(default_factory=dict)
    cells_by_kind: dict = field(default_factory=dict)
    estimated_rays: float = 0.0

    @property
    def overhead(self) -> float | None:
        if self.computed == 0 or self.wall_s <= 0 or self.workers <= 0:
            return None
        return max(0.0, 1.0 - self.compute_s / (self.workers * self.wall_s))

    def to_dict(self) -> dict:
        d = {k: getattr(self, k) for k in self.__dataclass_fields__}
        d["overhead"] = self.overhead
        d["complete"] = not self.failed and self.not_run == 0 and not self.dry_run
        return d


def check_scheduler_address(address: str) -> str:
    """``address`` if it has the form ``tcp://HOST:PORT`` (or tls://, ws://, wss://), else :class:`InputError`."""
    require_type("scheduler address", address, str, "e.g. 'tcp://10.0.0.5:8786'")
    m = _ADDRESS.match(address.strip())
    if not m or not 1 <= int(m.group(3)) <= 65535:
        raise InputError(f"the scheduler address must look like tcp://HOST:PORT (e.g. tcp://10.0.0.5:8786), "
                         f"got {address!r}")
    return address.strip()


def new_run_id() -> str:
    """A run's id: ``run_YYYYmmddTHHMMSSZ_xxxxxx`` (UTC time, 6 random hex digits)."""
    return time.strftime("run_%Y%m%dT%H%M%SZ", time.gmtime()) + "_" + secrets.token_hex(3)


def _check_folder(out: Path, dry_run: bool) -> Path:
    """The output folder, created and proven writable (a file written and removed); dry runs only look."""
    import tempfile

    if out.exists() and not out.is_dir():
        raise ExportError(f"{out} exists and is not a folder: give a folder for the library")
    if dry_run:
        p = out
        while not p.exists():
            p = p.parent
        if not p.is_dir() or not os.access(p, os.W_OK | os.X_OK):
            raise ExportError(f"cannot write into {out}: {p} is not a writable folder")
        return out
    try:
        out.mkdir(parents=True, exist_ok=True)
        fd, probe = tempfile.mkstemp(prefix=".physcam-probe-", dir=out)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise ExportError(f"cannot write into {out}: {exc.strerror or exc}") from None
    return out


def _check_lens(lens: Prescription, grid: Grid) -> None:
    """Every mark reachable, every f-stop within the lens's range: the errors a run would hit per cell."""
    from ..optics.focusing import focus
    from ..optics.state import camera_state

    for m in grid.focus_mm:
        try:
            focus(lens, m)
        except OpticsError as exc:
            raise InputError(f"lens {lens.name!r}: {exc}") from None
    for n in grid.fstops:
        try:
            camera_state(lens, fstop=n)  # the iris at that stop, by the one rule
        except OpticsError as exc:
            raise InputError(f"lens {lens.name!r}: {exc}") from None


def load_lenses(lenses):
    """{slug: Prescription} from names, files, Prescriptions, or a dict name -> Prescription."""
    from ..lens.library import load_lens

    if isinstance(lenses, (str, Path, Prescription)):
        lenses = [lenses]
    require_type("lenses", lenses, (list, tuple, dict), "lens names, files or Prescriptions")
    if not lenses:
        raise InputError("give at least one lens: the grid is empty")
    items = list(lenses.items()) if isinstance(lenses, dict) else [(None, v) for v in lenses]
    out = {}
    for key, item in items:
        if isinstance(item, Prescription):
            rx = item
        elif isinstance(item, (str, Path)) and key is None:
            rx = load_lens(item)
        else:
            raise WrongTypeError(f"a lens is a name, a file path or a Prescription, got {type(item).__name__}")
        if key is not None:
            require_type("lens name", key, str, "the lens's folder name")
            name = key
        elif isinstance(item, Path) or (isinstance(item, str) and ("/" in item or "\\" in item)):
            name = Path(str(item)).stem
        else:
            name = item if isinstance(item, str) else rx.name
        slug = lens_slug(name)
        if slug in out:
            raise InputError(f"lens {slug!r} is given twice")
        out[slug] = rx
    return out


def read_index(folder):
    """The library's Parquet index as a ``pyarrow.Table`` (one row per finished cell, every run).

    The index is a Parquet dataset: one small file per cell under ``FOLDER/index/LENS/KIND/``,
    each written atomically by the worker that made the cell, so any Parquet reader (pyarrow,
    DuckDB, pandas, Spark) can query the folder ``FOLDER/index`` while runs add to it.
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    from .cells import _schema

    require_type("folder", folder, (str, Path), "the library folder")
    files = sorted(Path(folder, "index").rglob("*.parquet"))
    schema = _schema()
    if not files:
        return schema.empty_table()
    return pa.concat_tables([_conformed(pq.read_table(f), schema) for f in files])


def _conformed(table, schema):
    """``table`` with ``schema``'s columns in its order: a row written before a column existed (the zoom
    columns) gets nulls there."""
    import pyarrow as pa

    for f in schema:
        if f.name not in table.column_names:
            table = table.append_column(f, pa.nulls(len(table), f.type))
    return table.select(schema.names).cast(schema)


def _connect(scheduler, workers, connect_timeout):
    """(client, cluster or None, dashboard link, seconds to start)."""
    t0 = time.perf_counter()
    from distributed import Client

    if scheduler is not None:
        try:
            client = Client(scheduler, timeout=connect_timeout, set_as_default=False)
        except (OSError, TimeoutError) as exc:
            raise InputError(f"cannot reach the Dask scheduler at {scheduler} within {connect_timeout:g} s "
                             f"({type(exc).__name__}); is it running, and is the address right?") from None
        return client, None, _dashboard(client), time.perf_counter() - t0
    cluster = local_cluster(workers)
    try:
        client = Client(cluster, set_as_default=False)
    except BaseException:
        cluster.close()
        raise
    return client, cluster, _dashboard(client), time.perf_counter() - t0


#: Worker environment of physcam's local cluster: one thread per worker for numba and the BLAS
WORKER_ENV = {"NUMBA_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


def local_cluster(workers: int):
    """A ``LocalCluster`` of ``workers`` single-threaded worker processes, with its dashboard.

    Dask's nannies start workers with ``MALLOC_TRIM_THRESHOLD_=65536`` (to hand memory back to the
    system early); that fixed threshold turns off glibc's adaptive one, so every large numpy
    temporary is unmapped when freed and faulted in again when the next is made: a 1e6-ray PSF
    cell took 0.25 s instead of 0.10 s (docs/performance.md). physcam's cells keep their memory
    bounded by chunking, so its cluster leaves the variable unset.
    """
    import logging

    import dask
    from distributed import LocalCluster

    with dask.config.set({"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}):
        return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0",
                            silence_logs=logging.ERROR, env=dict(WORKER_ENV))


def _dashboard(client):
    try:
        link = client.dashboard_link
    except Exception:  # noqa: BLE001 - no dashboard (bokeh missing on the scheduler)
        return None
    return link or None


def plan_cells(lenses: dict, grid: Grid, version: str) -> dict:
    """{slug: (the lens's physcam TOML, its hash, its cells)} for ``lenses`` ({slug: Prescription}) over
    the checked ``grid``, computed by physcam ``version``: the cells a run makes, whoever runs them (a
    Dask cluster here, a farm's tasks in :mod:`physcam.farm.grid_tasks`)."""
    from ..lens.formats.physcam_toml import dumps

    require_type("lenses", lenses, dict, "{slug: Prescription}")
    plan = {}
    for slug, rx in lenses.items():
        require_type("lens", rx, Prescription, "physcam.lens.library.load_lens(name)")
        digest = lens_hash(rx)
        plan[slug] = (dumps(rx), digest, build_cells(slug, digest, grid, rx.wavelength_nm, version))
    return plan


def characterize(lenses, grid: Grid, output, *, scheduler: str | None = None, workers: int | None = None,
                 limit: int | None = None, force_large: bool = False, dry_run: bool = False, retries: int = 2,
                 connect_timeout: float = DEFAULT_CONNECT_TIMEOUT_S, usd: bool = True, progress=None,
                 on_start=None, run_id: str | None = None) -> CharacterizeSummary:
    """Characterize ``lenses`` over ``grid`` into the folder ``output`` (module notes).

    ``lenses``: bundled lens names, lens files or Prescriptions. ``progress(done, total)`` is called
    as cells finish; ``on_start(summary)`` once the cluster is up (the dashboard address is in it).
    Raises :class:`InputError` / :class:`ExportError` for a bad grid, lens, address or folder before
    any cluster starts, and :class:`InputError` for a scheduler that cannot be reached.
    """
    from .. import __version__

    require_type("grid", grid, Grid, "physcam.characterize.Grid(focus_mm=..., fstops=...)")
    require_type("output", output, (str, Path), "a folder")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or not 1 <= workers <= 256):
        raise InputError(f"workers must be a whole number from 1 to 256, got {workers!r}")
    if limit is not None and (isinstance(limit, bool) or not isinstance(limit, int) or limit < 0):
        raise InputError(f"limit must be a whole number of cells >= 0, got {limit!r}")
    if isinstance(retries, bool) or not isinstance(retries, int) or not 0 <= retries <= 10:
        raise InputError(f"retries must be a whole number from 0 to 10, got {retries!r}")
    if isinstance(connect_timeout, bool) or not isinstance(connect_timeout, (int, float)) or \
            not 0.1 <= connect_timeout <= 600:
        raise InputError(f"the connect timeout must lie between 0.1 and 600 s, got {connect_timeout!r}")
    if scheduler is not None:
        scheduler = check_scheduler_address(scheduler)
        if workers is not None:
            raise InputError("--workers sizes a local cluster; an existing cluster (--scheduler) has its own workers")
    grid = grid.checked()
    loaded = load_lenses(lenses)
    for rx in loaded.values():
        _check_lens(rx, grid)
    out = _check_folder(Path(output), dry_run)
    run_id = run_id or new_run_id()

    plan = plan_cells(loaded, grid, __version__)
    all_cells = [c for _, _, cells in plan.values() for c in cells]
    n = len(all_cells)
    by_kind = {}
    for c in all_cells:
        by_kind[c.kind] = by_kind.get(c.kind, 0) + 1
    rays = by_kind.get("psf", 0) * grid.psf_rays + by_kind.get("illumination", 0) * grid.illumination_grid ** 2 * (
        max(grid.fields, 2) + 1)
    summary = CharacterizeSummary(run_id, str(out), list(loaded), n, grid=grid.to_dict(), cells_by_kind=by_kind,
                                  estimated_rays=float(rays), dry_run=dry_run)
    if n > HARD_MAX_CELLS or (n > MAX_CELLS and not force_large):
        raise InputError(f"the grid has {n:,} cells ({', '.join(f'{v:,} {k}' for k, v in by_kind.items())}); more "
                         f"than {MAX_CELLS:,} needs --force-large (force_large=True)"
                         + (f", and more than {HARD_MAX_CELLS:,} is refused" if n > HARD_MAX_CELLS else ""))
    if rays > MAX_RAYS and not force_large:
        raise InputError(f"the grid traces about {rays:.3g} rays, more than {MAX_RAYS:.0e}: lower --rays or "
                         "--grid, or pass --force-large (force_large=True)")
    todo = [c for c in all_cells if not (out / c.index_name).is_file()]
    summary.skipped = n - len(todo)
    if limit is not None:
        summary.not_run = max(0, len(todo) - limit)
        todo = todo[:limit]
    if dry_run:
        summary.not_run = len(todo) + summary.not_run
        return summary

    if todo:
        _compute(summary, plan, todo, grid, out, scheduler, workers, retries, connect_timeout, progress, on_start,
                 __version__)
    if usd:
        _update_usd(summary, loaded, plan, grid, out)
    return summary


#: Cell kinds that take milliseconds (a lens's breathing and pupils, relative illumination): one
#: Dask task computes all of a lens's cells of these kinds, so scheduling does not outweigh them
LIGHT_KINDS = ("lens", "illumination")


def task_groups(cells) -> list[list]:
    """The Dask tasks for ``cells``: each lens's light cells (:data:`LIGHT_KINDS`) together in one
    task, first; every other cell (ST-maps, PSF kernels: a tenth of a second and more) a task of its
    own, in the order given."""
    light: dict[str, list] = {}
    heavy = []
    for c in cells:
        if c.kind in LIGHT_KINDS:
            light.setdefault(c.lens, []).append(c)
        else:
            heavy.append([c])
    return list(light.values()) + heavy


def _compute(summary, plan, todo, grid, out, scheduler, workers, retries, connect_timeout, progress, on_start,
             version):
    from distributed import as_completed

    from .cells import run_cells

    nworkers = workers or os.cpu_count() or 1
    client, cluster, dash, started = _connect(scheduler, nworkers, connect_timeout)
    try:
        summary.scheduler = client.scheduler.address
        summary.dashboard = dash
        summary.cluster_start_s = started
        summary.workers = len(client.scheduler_info(n_workers=-1).get("workers", {})) or nworkers
        if on_start is not None:
            on_start(summary)
        t0 = time.perf_counter()
        futures, groups = [], task_groups(todo)
        for g in groups:
            toml, digest, _ = plan[g[0].lens]
            futures.append(client.submit(run_cells, toml, digest, g, grid, str(out.resolve()), summary.run_id,
                                         version, key=f"physcam-{summary.run_id}-{g[0].input_hash[:24]}",
                                         retries=retries, pure=False))
        done = 0
        try:
            for fut in as_completed(futures, loop=client.loop):
                group = groups[futures.index(fut)]
                try:
                    results = fut.result()
                except PhysCamError:
                    raise
                except Exception as exc:  # noqa: BLE001 - a task that failed after its retries, or KilledWorker
                    why = f"{type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}"
                    results = [{"status": "failed", "cell": c, "error": why} for c in group]
                for res in results:
                    if res["status"] == "computed":
                        summary.computed += 1
                        summary.compute_s += float(res["row"]["compute_s"])
                    elif res["status"] == "present":
                        summary.present += 1
                    else:
                        c = res["cell"]
                        summary.failed.append({"lens": c.lens, "kind": c.kind, "cell": c.stem, "error": res["error"]})
                done += len(group)
                if progress is not None:
                    progress(done, len(todo))
        except BaseException:
            client.cancel(futures)
            raise
        summary.wall_s = time.perf_counter() - t0
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _update_usd(summary, loaded, plan, grid, out) -> None:
    """Add a characterization variant to each complete lens's USD file (module notes)."""
    from .library import lens_usd_update

    failed_lenses = {f["lens"] for f in summary.failed}
    for slug, rx in loaded.items():
        _, digest, cells = plan[slug]
        if slug in failed_lenses or not all((out / c.index_name).is_file() for c in cells):
            continue
        res = lens_usd_update(rx, slug, cells, grid, out, summary.run_id)
        if res is not None:
            summary.usd.append(res)
