"""Building the Blender extension: CPU seconds per lens (``lens_payload``: its focus table, pupil tables and shaders).

Run:  .venv/bin/python benchmarks/blender_extension.py [--lenses dgauss_50mm,tessar_50mm]
                                                       [--baseline-src <other checkout>/src]
      .venv/bin/python benchmarks/blender_extension.py --build [--workers 2] [--baseline-src ...] [--install]
      .venv/bin/python benchmarks/blender_extension.py --build --issue47 --repeat 5 --baseline-src <main>/src

``--build``: the whole command instead (``physcam export blender-extension --workers N``, the lenses
given or every bundled one), its CPU seconds as user + system of the process and its workers
(``os.wait4``: forked or spawned, they are its children), with the zip's size: the part outside ``lens_payload``
too (worker start-up, the zip's deflate), one side after the other; with ``--baseline-src``, whether each lens's
files in the two zips (``lenses/<slug>.json``, ``shaders/<slug>.osl``) are the same bytes. ``--issue47``: with
``--build``, issue 47's row exactly: the 19 lenses bundled when it was filed (:data:`ISSUE_47_LENSES`, the 18 files
of the library before 43f450d7, and ``double_gauss_50mm_f2``, then a copy of ``dgauss_50mm``, since dropped: here
``dgauss_50mm``'s file copied under that name, so it is built twice as it was then). ``--repeat N``: with
``--build``, N runs of each side, the sides alternated (this checkout first in odd runs, the baseline first in even
ones), and each side's median. ``--rims``: the pupil tables' rims found along lines against the aim grids'
(:func:`main_rims`), no timing.
``--norms``: the centre's normalisation in closed form against a dense trace (:func:`main_norms`), no timing.
``--table``: one lens's radial pupil table by a library call (``radial_pupil_table``, "auto": numba not loaded
first) in a fresh process, then its whole payload (``lens_payload``: the tables of every focus state), each call's
CPU seconds and whether numba got loaded, ``--repeat`` times alternated with ``--baseline-src``'s, and whether the
two sides' outputs are the same bytes (:func:`main_table`; round 22's before/after).
``--install``: then Blender's installer of each side's zip
(``package_install_files`` in a fresh user folder, the Blender tests' way; the Blender of
``physcam.export.blender_runner.find_blender``), its wall and CPU seconds and the megabytes it unpacks.

Goal (issue 41 follow-up): every bundled lens in under ~2.5 min of CPU (the extension build was
about 8 min). CPU time (``time.process_time``: every thread of the process), so the figure holds on a
shared machine; the load average is printed with it. One process per lens, the JIT kernel loaded before the
clock starts (a whole build's "auto" backend switches to it within its first lens).

With ``--baseline-src`` the same lenses are measured with that checkout's physcam too (a subprocess with
``PYTHONPATH=<src>``, one lens of each side in turn, so both see the same load), and the ratio is printed
with the largest difference between the two sides' pupil tables (``FocusTable.radial``: per entry the
change of cx, ax and ay over the entry's size max(ax, ay); the area's relative change where both sides
trust it, and the entries whose trust differs) and norm tables (relative), at the iris levels both sides
tabulate.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

import numpy as np


#: Issue 47's "physcam export blender-extension (19 lenses)": the library's 18 files before 43f450d7 (which added 12
#: patent lenses), and ``double_gauss_50mm_f2`` (:data:`ISSUE_47_COPY`), a copy of ``dgauss_50mm`` then.
ISSUE_47_LENSES = ("canon_rf_85mm_f1_2", "cooke_triplet_50mm_f4_5", "dgauss_50mm", "dgauss_77deg_3_5201mm",
                   "double_gauss_100mm_f1_7", "fisheye_10mm", "mamiya_150mm_f4_soft", "mamiya_55mm_f2_8",
                   "navarro_anamorphic_2x", "neil_front_anamorphic_2x", "nikkor_fisheye_16mm_f2_8", "petzval_85mm_f2_4",
                   "sonnar_50mm_f1_5", "telephoto_250mm", "tessar_50mm_f2_8", "zeiss_distagon_35mm_f4",
                   "zeiss_planar_80mm_f2_8", "zuiko_18mm_f3_5")
#: The issue's 19th lens: (its slug then, the bundled lens whose copy it was).
ISSUE_47_COPY = ("double_gauss_50mm_f2", "dgauss_50mm")


def issue47_lenses(tmp: str) -> list[str]:
    """:data:`ISSUE_47_LENSES` and the copy's lens file, written in ``tmp`` under the slug it had."""
    from physcam.lens.library import library_dir

    slug, of = ISSUE_47_COPY
    path = os.path.join(tmp, f"{slug}.toml")
    with open(library_dir() / f"{of}.toml", "rb") as src, open(path, "wb") as dst:
        dst.write(src.read())
    return list(ISSUE_47_LENSES) + [path]


def load() -> str:
    return ", ".join(f"{v:.2f}" for v in os.getloadavg())


def worker(lens_name: str, out: str) -> None:
    """Build one lens's payload in this process: print its CPU seconds as JSON, save its tables to ``out``."""
    import physcam.export.blender_focus as bf
    from physcam.export.blender_extension import lens_payload
    from physcam.lens.library import load_lens
    from physcam.optics.focusing import focus
    from physcam.trace.kernels import get_kernel
    from physcam.trace.trace import camera_rays

    lens = load_lens(lens_name)
    # the JIT kernel loaded and compiled off the clock: a whole build switches to it within its first lens
    get_kernel("numba")
    st = focus(lens, math.inf)
    camera_rays(st.prescription, np.zeros((4, 2)), np.full((4, 2), 0.5), st.film_z, backend="numba")
    kept = {}
    inner = bf.focus_table

    def recording(*a, **k):
        kept["ft"] = ft = inner(*a, **k)
        return ft

    bf.focus_table = recording
    import physcam.export.blender_zoom as bz  # a zoom lens's tables (lens_payload imports it when called)

    inner_zoom = bz.zoom_focus_table

    def recording_zoom(*a, **k):
        kept["ft"] = ft = inner_zoom(*a, **k)
        return ft

    bz.zoom_focus_table = recording_zoom
    t = time.process_time()
    lens_payload(lens, lens_name)
    cpu = time.process_time() - t
    ft = kept["ft"]
    np.savez(out, radial=ft.radial if ft.radial is not None else np.zeros(0), norm=ft.norm,
             levels=np.asarray(ft.levels, dtype=float))
    print(json.dumps({"lens": lens_name, "cpu_s": cpu, "src": os.path.dirname(os.path.dirname(bf.__file__))}))


def table_worker(lens_name: str) -> None:
    """One lens's radial pupil table (focused at 2.5 m, at its iris levels) by a library call in this fresh
    process, "auto" backend, nothing loaded first: print the call's CPU seconds, whether numba was loaded after
    it and the table's sha1, as JSON."""
    import hashlib

    from physcam.export.blender_pupil import iris_levels, radial_pupil_table
    from physcam.lens.library import load_lens
    from physcam.optics.focusing import focus

    st = focus(load_lens(lens_name), 2500.0)
    q = st.prescription
    stop = q.surfaces[q.stop_index].semi_diameter
    levels = iris_levels(stop * 1.05, stop)
    t = time.process_time()
    table = radial_pupil_table(q, st.film_z, levels)
    cpu = time.process_time() - t
    from physcam.export.blender_extension import lens_payload

    t = time.process_time()
    data, _ = lens_payload(load_lens(lens_name), lens_name)
    payload = time.process_time() - t
    print(json.dumps({"cpu_s": cpu, "payload_s": payload, "numba": "numba" in sys.modules,
                      "sha1": hashlib.sha1(table.tobytes() + json.dumps(data).encode()).hexdigest()}))


def main_table(args, here: str) -> None:
    """``--table`` (module notes): per lens, ``--repeat`` runs of each side alternated, each side's median."""
    env = {k: v for k, v in os.environ.items() if k != "PHYSCAM_BACKEND"}
    env.setdefault("OPENBLAS_NUM_THREADS", "1")

    def one(src, name):
        r = subprocess.run([sys.executable, __file__, "--table-worker", name], env=dict(env, PYTHONPATH=os.path.abspath(src)),
                           capture_output=True, text=True, check=True)
        return json.loads(r.stdout.strip().splitlines()[-1])

    print(f"load average before: {load()}, mark {mark():.1f} ms")
    for name in (args.lenses.split(",") if args.lenses else ["dgauss_50mm", "canon_rf_85mm_f1_2"]):
        sides = {"this": (here, []), "base": (args.baseline_src, [])} if args.baseline_src else {"this": (here, [])}
        for i in range(args.repeat):
            for side in (list(sides) if i % 2 == 0 else list(sides)[::-1]):
                sides[side][1].append(one(sides[side][0], name))
        for side, (_, rows) in sides.items():
            cpu, pay = sorted(r["cpu_s"] for r in rows), sorted(r["payload_s"] for r in rows)
            print(f"{name:24s} {side:5s} table CPU median {cpu[len(cpu) // 2]:.3f} s ({cpu[0]:.3f}-{cpu[-1]:.3f}), then"
                  f" its payload {pay[len(pay) // 2]:.3f} s ({pay[0]:.3f}-{pay[-1]:.3f}); numba loaded:"
                  f" {sorted({r['numba'] for r in rows})}, sha1 {sorted({r['sha1'][:12] for r in rows})}")
    print(f"load average after: {load()}, mark {mark():.1f} ms")


def run(lens_name: str, src: str | None, out: str) -> float:
    env = dict(os.environ)
    # numpy's BLAS on one thread, as the `physcam` program runs it (physcam.cli.run; its build's workers inherit
    # it): with OpenBLAS's default two threads the fill between marks (fill_pupil_tables' small matrix products,
    # 4.4 ms of CPU each against 0.23 ms) made a lens's payload about 7 % dearer here than in the build
    env.setdefault("OPENBLAS_NUM_THREADS", "1")
    if src:
        env["PYTHONPATH"] = os.path.abspath(src)
    r = subprocess.run([sys.executable, __file__, "--worker", lens_name, "--out", out], env=env,
                       capture_output=True, text=True)
    if r.returncode:
        sys.exit(f"{lens_name} failed ({src or 'this checkout'}): {r.stderr.strip().splitlines()[-1]}")
    row = json.loads(r.stdout.strip().splitlines()[-1])
    if src and not os.path.samefile(os.path.dirname(row["src"]), os.path.abspath(src)):
        sys.exit(f"the baseline ran {row['src']}, not {src}: is physcam installed non-editable?")
    return row["cpu_s"]


def build(src: str | None, names, workers: int, out: str) -> tuple[float, float, float, int]:
    """(user CPU s, system CPU s, wall s, zip bytes) of one whole ``physcam export blender-extension`` in a
    fresh process with ``PYTHONPATH=<src>`` (its worker processes' CPU included: ``os.wait4``)."""
    env = dict(os.environ)
    if src:
        env["PYTHONPATH"] = os.path.abspath(src)
    cmd = [sys.executable, "-m", "physcam", "export", "blender-extension", "-o", out, "--workers", str(workers), "--force"]
    for name in names or ():
        cmd += ["--lens", name]
    t = time.perf_counter()
    p = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, ru = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t
    if os.waitstatus_to_exitcode(status):
        sys.exit(f"the build failed ({src or 'this checkout'}): {p.stderr.read().decode().strip().splitlines()[-1]}")
    (zp,) = [f for f in os.listdir(out) if f.endswith(".zip")]
    return ru.ru_utime, ru.ru_stime, wall, os.path.getsize(os.path.join(out, zp))


_INSTALL = """
import os, json, sys, time
import bpy
t, c = time.perf_counter(), time.process_time()
bpy.ops.extensions.package_install_files(filepath=sys.argv[-1], repo="user_default", enable_on_install=True)
print(json.dumps({"wall_s": time.perf_counter() - t, "cpu_s": time.process_time() - c}))
"""


def install(zip_path: str, tmp: str) -> tuple[float, float, float]:
    """(wall s, CPU s, MB unpacked) of Blender's installer of ``zip_path`` into a fresh user folder."""
    from physcam.export.blender_runner import find_blender

    user, script = os.path.join(tmp, "user"), os.path.join(tmp, "install.py")
    with open(script, "w") as fh:
        fh.write(_INSTALL)
    r = subprocess.run(find_blender().command(script, zip_path), capture_output=True, text=True,
                       env=dict(os.environ, BLENDER_USER_RESOURCES=user), check=True)
    row = json.loads([ln for ln in r.stdout.splitlines() if ln.startswith("{")][-1])
    size = sum(os.path.getsize(os.path.join(d, f)) for d, _, fs in os.walk(os.path.join(user, "extensions")) for f in fs)
    return row["wall_s"], row["cpu_s"], size / 1e6


def main_build(args, here: str) -> None:
    sides = [("this checkout", here)] + ([("baseline", args.baseline_src)] if args.baseline_src else [])
    print(f"load average before: {load()}, mark {mark():.1f} ms")
    cpu, zips = {label: [] for label, _ in sides}, {}
    with tempfile.TemporaryDirectory() as tmp:
        names = (issue47_lenses(tmp) if args.issue47 else args.lenses.split(",") if args.lenses else None)
        for k in range(args.repeat):
            for label, src in (sides if k % 2 == 0 else sides[::-1]):
                out = os.path.join(tmp, label.replace(" ", "_"))
                os.makedirs(out, exist_ok=True)
                user, system, wall, size = build(src, names, args.workers, out)
                cpu[label].append(user + system)
                print(f"{label:14s} CPU {user + system:7.1f} s (user {user:.1f}, system {system:.1f}), wall {wall:6.1f} s, "
                      f"zip {size / 1e6:.1f} MB, load {load()}, mark {mark():.1f} ms", flush=True)
                (zips[label],) = [os.path.join(out, f) for f in os.listdir(out) if f.endswith(".zip")]
                if args.install and k == 0:
                    i_wall, i_cpu, i_mb = install(zips[label], out)
                    print(f"{label:14s} Blender install: wall {i_wall:.1f} s, CPU {i_cpu:.1f} s, {i_mb:.1f} MB unpacked",
                          flush=True)
        if args.baseline_src:
            same, differ = same_lens_files(zips["baseline"], zips["this checkout"])
            print(f"lens files (lenses/*.json, shaders/*.osl) byte for byte the baseline's: {same} of {same + len(differ)}"
                  + (f"; differ: {', '.join(differ[:8])}{' ...' if len(differ) > 8 else ''}" if differ else ""))
    med = {label: float(np.median(v)) for label, v in cpu.items()}
    if args.repeat > 1:
        print("median CPU s of " + str(args.repeat) + ": " + ", ".join(f"{label} {m:.2f}" for label, m in med.items()))
    if args.baseline_src:
        print(f"ratio (baseline / this){' of the medians' if args.repeat > 1 else ''}: "
              f"{med['baseline'] / med['this checkout']:.3f}")


def mark() -> float:
    """The machine's mark (the project's): milliseconds of ``sum(range(10**6))`` in this process."""
    t = time.perf_counter()
    sum(range(10**6))
    return (time.perf_counter() - t) * 1e3


def round_states(name):
    """The focus states ``--rims`` and ``--norms`` check for the lens ``name``, none for an anamorphic: at infinity and
    the closest focus (a zoom at both ends), each (zoom position or None, focus distance, prescription, film z, iris
    levels from 1.03 times the file's stop)."""
    from physcam.export.blender_pupil import iris_levels
    from physcam.lens.library import load_lens
    from physcam.lens.zoom import prescription_at
    from physcam.optics.focusing import closest_focus, focus

    lens0 = load_lens(name)
    if lens0.is_anamorphic:
        return
    for u in ([0.0, 1.0] if lens0.zoom is not None else [None]):
        lens = lens0 if u is None else prescription_at(lens0, u)
        for d in (math.inf, closest_focus(lens) * 1.0001):
            st = focus(lens, d)
            q = st.prescription
            semi = q.surfaces[q.stop_index].semi_diameter
            yield u, d, q, st.film_z, iris_levels(semi * 1.03, semi)


def main_rims(names) -> None:
    """``--rims``: per lens with rotational symmetry, at infinity and the closest focus (a zoom at both ends), every
    rim the pupil tables find along lines (``blender_pupil_sets._LineSets``) against the aim grids' at the same film and
    iris radius (``_PassingSets`` without lines: the dense search), and the largest and smallest ratio against a dense trace
    (400 x 200 aims over the y >= 0 half of its ellipse's box, 1.25x): areas, and the dense passing aims outside
    the ellipse fitted to the lines' rim."""
    import physcam.export.blender_pupil as bp
    import physcam.export.blender_pupil_sets as bps
    from physcam.trace.kernels import resolve_backend
    from physcam.trace.rays import OK, RayBatch
    from physcam.trace.trace import trace_through

    resolve_backend("auto")
    every = []
    for name in names:
        rels, ends, points = [], {}, 0
        for u, d, q, film_z, levels in round_states(name):
            fine = np.sort(np.concatenate([levels, np.sqrt(levels[:-1] * levels[1:])]))[::-1]
            g = bp._PassingSets(q, film_z, levels, "numba", finer=True)
            ln = bp._PassingSets(q, film_z, levels, "numba", finer=True, lines=True)
            for sets in (g, ln):
                sets.need(levels)
                sets.need(fine)
            points += ln.lines.points.size
            served = np.zeros_like(ln.have)
            served[ln.lines.points] = np.arange(ln.radii.size)[None, :] >= ln.lines.first[:, None]
            both = served & ln.have & (g.index >= 0) & (ln.index >= 0)
            rel = ln.rims.area[ln.index[both]] / g.rims.area[g.index[both]] - 1
            rels.append(rel)
            for side, pick in (("largest", np.argmax), ("smallest", np.argmin)):
                if rel.size:
                    i = int(pick(rel))
                    if side not in ends or (rel[i] > ends[side][0]) == (side == "largest"):
                        p, r = (a[i] for a in np.nonzero(both))
                        ends[side] = (rel[i], q, film_z, g, ln, p, r, u, d)
        if not rels:  # an anamorphic: no states
            continue
        rel = np.concatenate(rels)
        every.append(rel)
        text = []
        for side, (r_, q, film_z, g, ln, p, r, u, d) in ends.items():
            s, rho = g.radii[r], g.rhos[p]
            cx, ax, ay, a_l = bps._fits(ln.rims, np.array([ln.index[p, r]]))[0]
            gx, gy = np.meshgrid(cx + ((np.arange(400) + 0.5) / 400 * 2 - 1) * 1.25 * ax,
                                 (np.arange(200) + 0.5) / 200 * 1.25 * ay)
            gx, gy = gx.ravel(), gy.ravel()
            rays = RayBatch.from_arrays(np.broadcast_to([rho, 0.0, film_z], (gx.size, 3)),
                                        np.stack([gx - rho, gy, np.full(gx.size, q.vertex_z[-1] - film_z)], axis=1),
                                        q.wavelength_nm)
            trace_through(q, rays, reverse=True, clip=True, stop_semi_diameter=s, in_place=True)
            ok = rays.flag == OK
            dense = 2 * ok.sum() / gx.size * (2.5 * ax) * (1.25 * ay)
            out = int((((gx[ok] - cx) / ax) ** 2 + (gy[ok] / ay) ** 2 > 1).sum())
            text.append(f"{side} {r_:+.4f} (film radius {rho:.2f} mm, iris {s:.3f} mm" + (f", zoom {u}" if u is not None else "")
                        + f", focus {d:.0f} mm; against a dense trace: lines {a_l / dense - 1:+.4f}, grids "
                        f"{g.rims.area[g.index[p, r]] / dense - 1:+.4f}, passing aims outside the lines' ellipse {out} of "
                        f"{int(ok.sum())})")
        print(f"{name}: {points} film points on lines, {rel.size} rims; lines / grids - 1 median {np.median(rel):+.4f}, "
              + "; ".join(text), flush=True)
    rel = np.concatenate(every)
    print(f"all: {rel.size} rims, lines / grids - 1 median {np.median(rel):+.4f}, 99 % of |.| under "
          f"{np.quantile(np.abs(rel), 0.99):.4f}, largest |.| {np.abs(rel).max():.4f}")


def main_norms(names) -> None:
    """``--norms``: per lens with rotational symmetry, at infinity and the closest focus (a zoom at both ends), the
    centre's normalisation in closed form (``blender_focus._centre_disk_norms``) at the widest iris, the file's stop,
    the 10th level and the last, against the mean weight of physcam's camera rays from the film centre over a
    1024 x 1024 grid of aims on a square 1.02 times the disk's radius, the iris stopped to the level."""
    from physcam.export.blender_focus import _centre_disk_norms
    from physcam.trace.kernels import resolve_backend
    from physcam.trace.pupil_bounds import PupilBounds
    from physcam.trace.trace import camera_rays

    resolve_backend("auto")
    m = 1024
    u = (np.arange(m) + 0.5) / m
    uv = np.stack([a.ravel() for a in np.meshgrid(u, u)], axis=1)
    every = []
    for name in names:
        for zu, d, q, film_z, levels in round_states(name):
            norms = _centre_disk_norms(q, film_z, levels, "numba")
            if norms is None:
                print(f"{name} at {d:.0f} mm: not a disk (the grid estimate serves)")
                continue
            dz = film_z - q.vertex_z[-1]
            rel = []
            for k in (0, 1, 9, len(levels) - 1):
                h = 1.02 * math.sqrt(norms[k] * dz * dz / (math.pi - norms[k]))
                rect = np.broadcast_to(np.array([-h, h, -h, h]), (2, 2, 4)).copy()
                b = PupilBounds(np.array([-1.0, 1.0]), np.array([-1.0, 1.0]), rect, float(q.vertex_z[-1]))
                cr = camera_rays(q, np.zeros((uv.shape[0], 2)), uv, film_z, bounds=b, stop_semi_diameter=float(levels[k]))
                rel.append(norms[k] / float(np.mean(np.where(cr.ok, cr.weight, 0.0))) - 1)
            every += rel
            print(f"{name}" + (f" zoom {zu}" if zu is not None else "") + f" at {d:.0f} mm: closed form / dense - 1 at "
                  "the widest iris, the file's stop, levels 10 and last: " + ", ".join(f"{r:+.1e}" for r in rel), flush=True)
    print(f"all: {len(every)} norms, closed form / dense - 1 from {min(every):+.1e} to {max(every):+.1e}")


def same_lens_files(zip_a: str, zip_b: str) -> tuple[int, list[str]]:
    """(how many of the two zips' per-lens files are the same bytes, the names of those that are not or are
    in one zip only): each lens's JSON table and shader source."""
    import zipfile

    with zipfile.ZipFile(zip_a) as a, zipfile.ZipFile(zip_b) as b:
        names = sorted({n for z in (a, b) for n in z.namelist() if n.startswith(("lenses/", "shaders/"))})
        na, nb = set(a.namelist()), set(b.namelist())
        differ = [n for n in names if n not in na or n not in nb or a.read(n) != b.read(n)]
    return len(names) - len(differ), differ


def table_change(old: dict, new: dict) -> dict:
    """The largest differences between two sides' tables of one lens (module notes), at the iris levels both
    tabulate (a lens's refined levels may differ: the levels a side adds, :func:`_refined_levels`, are left out)."""
    a, b, na, nb = old["radial"], new["radial"], old["norm"], new["norm"]
    if "levels" in old and "levels" in new and a.ndim == 4 and b.ndim == 4:  # (marks, levels, radii, 5)
        la, lb = old["levels"], new["levels"]
        common = np.intersect1d(la, lb)
        ia, ib = np.searchsorted(-la, -common[::-1]), np.searchsorted(-lb, -common[::-1])
        a, b, na, nb = a[:, ia], b[:, ib], na[:, ia], nb[:, ib]
    if a.shape != b.shape or na.shape != nb.shape:  # another grid of radii or levels
        return {"ellipse": math.nan, "area": math.nan, "trust_flips": -1, "norm": math.nan, "trusted": (-1, -1)}
    out = {"norm": float(np.max(np.abs(nb / na - 1)))}
    if a.size == 0:
        return out | {"ellipse": 0.0, "area": 0.0, "trust_flips": 0, "trusted": (0, 0)}
    size = np.maximum(a[..., 1], a[..., 2])
    out["ellipse"] = float(np.max(np.abs(b[..., :3] - a[..., :3]) / size[..., None]))
    both = (a[..., 3] > 0) & (b[..., 3] > 0)
    out["area"] = float(np.max(np.abs(b[..., 3][both] / a[..., 3][both] - 1), initial=0.0))
    out["trust_flips"] = int(np.sum((a[..., 3] < 0) != (b[..., 3] < 0)))
    out["trusted"] = (int(np.sum(a[..., 3] > 0)), int(np.sum(b[..., 3] > 0)))  # entries whose area is trusted, each side
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--lenses", help="comma-separated bundled slugs (default: every bundled lens)")
    ap.add_argument("--baseline-src", help="another checkout's src directory to compare against")
    ap.add_argument("--build", action="store_true", help="time the whole CLI build (module notes)")
    ap.add_argument("--workers", type=int, default=2, help="--build's worker processes (default 2)")
    ap.add_argument("--install", action="store_true", help="--build: time Blender's installer of each zip too")
    ap.add_argument("--issue47", action="store_true", help="--build: issue 47's 19 lenses (ISSUE_47_LENSES, module notes)")
    ap.add_argument("--repeat", type=int, default=1, help="--build: runs of each side, alternated; medians printed")
    ap.add_argument("--rims", action="store_true", help="the pupil tables' rims along lines against the aim grids' "
                    "(main_rims)")
    ap.add_argument("--norms", action="store_true", help="the centre's normalisation in closed form against a dense trace "
                    "(main_norms)")
    ap.add_argument("--table", action="store_true", help="one lens's pupil table by a library call, alternated with "
                    "--baseline-src's (main_table)")
    ap.add_argument("--table-worker", help=argparse.SUPPRESS)
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    ap.add_argument("--out", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        return worker(args.worker, args.out)
    if args.table_worker:
        return table_worker(args.table_worker)
    from physcam.lens.library import list_lenses

    here = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src")
    if args.build:
        return main_build(args, here)
    if args.table:
        return main_table(args, here)
    names = args.lenses.split(",") if args.lenses else [r.slug for r in list_lenses()]
    if args.rims:
        return main_rims(names)
    if args.norms:
        return main_norms(names)
    print(f"load average before: {load()}")
    head = f"{'lens':28s} {'this CPU s':>10s}"
    if args.baseline_src:
        head += (f" {'base CPU s':>10s} {'ratio':>6s} {'ellipse':>9s} {'area':>9s} {'flips':>5s} {'norm':>9s}"
                 f" {'trusted (base -> this)':>22s}")
    print(head)
    tot, tot_b, worst = 0.0, 0.0, {"ellipse": 0.0, "area": 0.0, "trust_flips": 0, "norm": 0.0}
    incomparable = 0  # lenses whose two sides tabulate other radii or levels (their nan left out of worst)
    with tempfile.TemporaryDirectory() as tmp:
        for name in names:
            new_f, old_f = os.path.join(tmp, "new.npz"), os.path.join(tmp, "old.npz")
            cpu = run(name, here, new_f)
            tot += cpu
            line = f"{name:28s} {cpu:10.2f}"
            if args.baseline_src:
                base = run(name, args.baseline_src, old_f)
                tot_b += base
                d = table_change(dict(np.load(old_f)), dict(np.load(new_f)))
                incomparable += d["trust_flips"] < 0
                worst = {k: max(worst[k], d[k]) for k in worst}  # (trusted: per lens only)
                line += (f" {base:10.2f} {base / cpu:6.2f} {d['ellipse']:9.2e} {d['area']:9.2e} {d['trust_flips']:5d}"
                         f" {d['norm']:9.2e} {d['trusted'][0]:>10d} -> {d['trusted'][1]:<8d}")
            print(line, flush=True)
    print(f"{'total':28s} {tot:10.2f}" + (f" {tot_b:10.2f} {tot_b / tot:6.2f}" if args.baseline_src else ""))
    if args.baseline_src:
        print("largest change over every lens: ellipse {ellipse:.2e} of its size, area {area:.2e}, "
              "{trust_flips} entries whose area trust differs, norm {norm:.2e}".format(**worst)
              + (f" (over the others: {incomparable} lens(es) tabulated on other radii or levels, not compared)"
                 if incomparable else ""))
    print(f"load average after: {load()}")


if __name__ == "__main__":
    main()
