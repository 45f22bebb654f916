"""Tube throughput: spinal.tube vs VTK (PyVista ``tube``) and trimesh ``sweep_polygon``.

Same spine (a helix), same number of sides, one run. For every size it times

* ``spinal.tube(points, r, sides)`` — frames (double reflection) + mesh with normals and uv,
  float64 triangles, watertight with caps;
* ``spinal.tube(..., dtype=np.float32)`` — the same mesh stored in float32, int32 faces;
* ``spinal.tube(..., dtype=np.float32, uv=False)`` — float32 vertices and normals, int32
  faces: the outputs VTK's tube filter gives (points, normals, connectivity);
* VTK via PyVista on one polyline, ``PolyData.tube`` — vtkTubeFilter, triangle strips with
  float64 points (the input's precision), float32 normals and int64 connectivity (less
  output: no uv, strips instead of triangles); the same on float32 points (float32 points
  out: the like-for-like peer of spinal float32 without uv); and ``+ .triangulate()``
  (vtkTriangleFilter) for a triangle mesh like ours;
* VTK on ``pyvista.lines_from_points(points)`` — one line cell per segment, so a separate
  capped ring pair for every segment (4× the vertices; not the same surface);
* ``trimesh.creation.sweep_polygon`` when shapely is installed (skipped otherwise);
* the NumPy floor: allocating and writing arrays of the size of spinal's float64 output once.

and prints a float64 table with the ratios, then the float32 table against VTK. The default
run adds 1 000 curves of 1 000 points (spinal in one call with ``lengths``; VTK one PolyData
with 1 000 polylines; ``--no-bundle`` leaves it out). ``--bundle`` adds the big bundle:
100 000 streamlines of 96 points (9.6 M points, 8 sides), time and peak memory of every
call measured in a fresh process (spinal float32, VTK strips and the NumPy write floor of
spinal float32's output; ``--bundle-all`` adds spinal float64 and VTK strips +
triangulate), each after the same call once (its output freed just before, so the measured
call reuses warm pages). ``--bundle-first`` measures first calls instead, each after a pause:
on a virtual machine that hands freed memory back to its host (free page reporting: on the
machine measured, 2 MiB blocks from ~2 s after they are freed, ~250 MB/s), the first touch
of memory so handed back costs more than the sweep (writing 2 GB with NumPy there took
0.7 s of system time right after another process freed 4 GB, 5.8 s after a 40 s pause), so
a first call's time depends on what ran before it.

    python benchmarks/bench_sweep.py              # 10^3 … 10^6 spine points
    python benchmarks/bench_sweep.py --max 2e5
    python benchmarks/bench_sweep.py --bundle     # + the 100k-streamline bundle (~5 GB)
    python benchmarks/bench_sweep.py --bundle --bundle-first   # first calls, cold memory
    python benchmarks/bench_sweep.py --spikes     # only: non-convex profiles of 10^3 … 10^5
                                                  # packed spikes (star, comb), capped
    python benchmarks/bench_sweep.py --rough      # only: 2,000 Gaussian random walks and
                                                  # dipy's bundled tracts (when installed)
"""

from __future__ import annotations

import argparse
import itertools
import json
import subprocess
import sys
import time
import warnings

import numpy as np
from _timing import best, helix

import spinal

SIDES = 16
RADIUS = 0.05




def floor(nv, nf):
    # all four arrays alive at once, as in a mesh
    return (np.full((nv, 3), 1.0), np.full((nv, 3), 1.0), np.full((nv, 2), 1.0),
            np.full((nf, 3), 1))


def peers():
    out = {}
    try:
        import pyvista as pv

        out["pv"] = pv
    except ImportError:
        pass
    try:
        import shapely  # noqa: F401
        import trimesh

        out["trimesh"] = trimesh
    except ImportError:
        pass
    return out


def run(sizes, repeat, bundle):
    p = peers()
    rows = []
    cases = [(f"{n:,} points", [helix(n)]) for n in sizes]
    if bundle:
        rng = np.random.default_rng(0)
        cases.append(("1,000 curves × 1,000", [helix(1000, 3) + rng.normal(size=3) * 5
                                               for _ in range(1000)]))
    for label, curves in cases:
        x = np.concatenate(curves)
        lengths = [len(c) for c in curves]
        kw = {"lengths": lengths} if len(curves) > 1 else {}
        rep = repeat if len(x) <= 200_000 else max(2, repeat // 2)
        mesh = spinal.tube(x, RADIUS, SIDES, **kw)  # warm-up, and the output's size
        nv, nf = len(mesh.vertices), len(mesh.faces)
        del mesh
        res = {"case": label}
        res["spinal"] = best(lambda: spinal.tube(x, RADIUS, SIDES, **kw), rep)  # noqa: B023
        res["spinal float32"] = best(
            lambda: spinal.tube(x, RADIUS, SIDES, dtype=np.float32, **kw), rep)  # noqa: B023
        res["spinal float32 no uv"] = best(
            lambda: spinal.tube(x, RADIUS, SIDES, dtype=np.float32, uv=False, **kw),  # noqa: B023
            rep)
        res["floor"] = best(lambda: floor(nv, nf), rep)  # noqa: B023
        if "pv" in p:
            pv = p["pv"]
            cells = np.concatenate([np.r_[k, np.arange(k) + o]
                                    for k, o in zip(lengths, np.cumsum([0] + lengths[:-1]),
                                                    strict=True)])
            poly = pv.PolyData(x, lines=cells)
            res["vtk strips"] = best(lambda: poly.tube(radius=RADIUS, n_sides=SIDES, capping=True),  # noqa: B023
                                     rep)
            poly32 = pv.PolyData(x.astype(np.float32), lines=cells)
            res["vtk strips f32"] = best(
                lambda: poly32.tube(radius=RADIUS, n_sides=SIDES, capping=True), rep)  # noqa: B023
            res["vtk triangles"] = best(
                lambda: poly.tube(radius=RADIUS, n_sides=SIDES, capping=True).triangulate(),  # noqa: B023
                rep)
            if len(curves) == 1 and len(x) <= 1_000_000:
                seg = pv.lines_from_points(x)
                res["vtk lines_from_points"] = best(
                    lambda: seg.tube(radius=RADIUS, n_sides=SIDES, capping=True),  # noqa: B023
                    2 if len(x) <= 200_000 else 1)
        if "trimesh" in p and len(x) <= 100_000:
            import shapely

            a = 2 * np.pi * np.arange(SIDES) / SIDES
            poly2 = shapely.Polygon(np.c_[np.cos(a), np.sin(a)] * RADIUS)
            tm = p["trimesh"]

            def sweep_all():
                for c in curves:  # noqa: B023
                    tm.creation.sweep_polygon(poly2, c)  # noqa: B023

            res["trimesh sweep_polygon"] = best(sweep_all, 1)
        rows.append(res)
    return rows


BUNDLE_CHILD = r"""
import json, os, sys, time
import numpy as np
what, curves, per, sides = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
warm = sys.argv[5] == "warm"
rng = np.random.default_rng(0)
# smooth random streamlines: cumulative sums of slowly turning unit steps
n = curves * per
d = rng.normal(size=(curves, 3))[:, None, :] + 0.3 * np.cumsum(
    rng.normal(size=(curves, per, 3)) * 0.2, axis=1)
d /= np.linalg.norm(d, axis=2, keepdims=True)
x = np.ascontiguousarray((np.cumsum(d, axis=1) + rng.uniform(-50, 50, (curves, 1, 3)))
                         .reshape(n, 3))
del d
lengths = np.full(curves, per)
r = 0.2
def status(key):
    with open("/proc/self/status") as f:
        return next(int(l.split()[1]) for l in f if l.startswith(key)) * 1024
if what.startswith("spinal"):
    import spinal
    kw = {"dtype": np.float32} if what == "spinal float32" else {}
    run = lambda: spinal.tube(x, r, sides, lengths=lengths, **kw)
    small = lambda: spinal.tube(x[:per], r, sides)
    size = lambda m: sum(a.nbytes for a in (m.vertices, m.faces, m.normals, m.uv))
elif what == "numpy floor":
    # spinal float32's output arrays (vertices, normals, uv, int32 faces) written once
    nv, nf = n * sides, curves * (2 * (per - 1) * sides + 2 * (sides - 2))
    shapes = (((nv, 3), np.float32), ((nv, 3), np.float32), ((nv, 2), np.float32),
              ((nf, 3), np.int32))
    run = lambda: [np.full(s, 1, dtype=t) for s, t in shapes]
    small = lambda: np.full(1000, 1.0)
    size = lambda m: sum(a.nbytes for a in m)
else:
    import pyvista as pv
    cells = np.empty((curves, per + 1), dtype=np.int64)
    cells[:, 0] = per
    cells[:, 1:] = np.arange(n).reshape(curves, per)
    poly = pv.PolyData(x, lines=cells.ravel())
    del cells
    one = pv.PolyData(x[:per], lines=np.r_[per, np.arange(per)])
    if what == "vtk strips":
        run = lambda: poly.tube(radius=r, n_sides=sides, capping=True)
        small = lambda: one.tube(radius=r, n_sides=sides, capping=True)
    else:
        run = lambda: poly.tube(radius=r, n_sides=sides, capping=True).triangulate()
        small = lambda: one.tube(radius=r, n_sides=sides, capping=True).triangulate()
    size = lambda m: m.actual_memory_size * 1024
# warm-up: the whole call (its output's pages freed just before the measured call, which
# then reuses them), or for a first call one curve (imports, thread pool, code paths)
(run if warm else small)()
with open("/proc/self/clear_refs", "w") as f:
    f.write("5")
before = status("VmRSS:")
c0, t0 = os.times(), time.perf_counter()
out = run()
t, c1 = time.perf_counter() - t0, os.times()
print(json.dumps({"s": t, "user": c1.user - c0.user, "sys": c1.system - c0.system,
                  "peak": status("VmHWM:") - before, "output": size(out), "points": n}))
"""


def bundle_rows(curves=100_000, per=96, sides=8, everything=False, first=False, pause=60.0):
    """Time, CPU seconds and peak memory of each call on the big bundle, each in a fresh
    process (so the peaks do not mix); a call that fails (memory) is reported as such.
    ``everything`` adds spinal float64 (~9.3 GB) and VTK strips + triangulate (~8 GB). Every
    call is measured after the same call once, or with ``first`` as the first of its size in
    its process, started ``pause`` seconds after the previous one (see the module
    docstring)."""
    rows = []
    has_vtk = "pv" in peers()
    whats = ["spinal float32"] + (["vtk strips"] if has_vtk else []) + ["numpy floor"]
    if everything:
        whats += ["spinal float64"] + (["vtk triangles"] if has_vtk else [])
    for what in whats:
        if first:
            time.sleep(pause)
        r = subprocess.run([sys.executable, "-c", BUNDLE_CHILD, what, str(curves), str(per),
                            str(sides), "first" if first else "warm"],
                           capture_output=True, text=True, check=False)
        if r.returncode:
            rows.append((what, None, r.stderr.strip().splitlines()[-1:] or ["failed"]))
        else:
            rows.append((what, json.loads(r.stdout), None))
    return rows


def spiky(kind, m):
    """A simple polygon of ``m`` vertices with ``m / 2`` densely packed spikes: ``star``
    (radii alternating 1 and 0.2 about the origin) or ``comb`` (teeth of height 1 on a bar
    of height 0.1, as thin as they are apart)."""
    if kind == "star":
        t = 2 * np.pi * np.arange(m) / m
        r = np.where(np.arange(m) % 2 == 0, 1.0, 0.2)
        return np.c_[r * np.cos(t), r * np.sin(t)]
    k = (m - 3) // 4  # teeth of 4 vertices, right to left, after three bar corners
    x0 = np.repeat(np.arange(k)[::-1] / k, 4) + np.tile([0.5, 0.5, 0.0, 0.0], k) / k
    y = np.tile([0.1, 1.1, 1.1, 0.1], k)
    return np.r_[[[0.0, 0.0], [1.0, 0.0], [1.0, 0.1]], np.c_[x0, y]]


def spike_rows(repeat, limit=120.0):
    """Seconds of a capped sweep of each spiky profile along a straight 3-point spine, from
    ``m = 10^3`` up; a size stops the kind's row once a call takes longer than ``limit``."""
    spine = np.c_[np.zeros(3), np.zeros(3), np.arange(3.0)]
    print("| profile | m = 1,000 | 10,000 | 100,000 | time × per 10× m |")
    print("|---|---|---|---|---|")
    for kind in ("star", "comb"):
        ts = []
        for m in (1_000, 10_000, 100_000):
            prof = spiky(kind, m)
            t = best(lambda p=prof: spinal.sweep(spine, p), repeat)
            ts.append(t)
            if t > limit:
                break
        cells = [f"{t:.3g}" for t in ts] + ["–"] * (3 - len(ts))
        growth = " / ".join(f"{b / a:.0f}" for a, b in itertools.pairwise(ts)) or "–"
        print(f"| {kind} | " + " | ".join(cells) + f" | {growth} |", flush=True)


def rough_sets():
    """Rough polylines as users have them: 2,000 Gaussian random walks of 3…60 points, and
    dipy's bundled tracts when dipy is installed (fornix, EuDX small, the minimal bundles,
    the two cingulum bundles)."""
    rng = np.random.default_rng(0)
    yield "2,000 random walks", [np.cumsum(rng.normal(size=(rng.integers(3, 61), 3)), axis=0)
                                 for _ in range(2000)]
    try:
        import glob
        import os
        import tempfile
        import zipfile

        import dipy
        import dipy.data
        import nibabel as nib
    except ImportError:
        return
    files = os.path.join(os.path.dirname(dipy.__file__), "data", "files")

    def trk(*paths):
        return [np.asarray(s, dtype=float) for f in paths
                for s in nib.streamlines.load(f).streamlines]

    yield "dipy fornix", trk(os.path.join(files, "tracks300.trk"))
    yield "dipy EuDX small", trk(os.path.join(files, "EuDX_small_25.trk"))
    with tempfile.TemporaryDirectory() as tmp:
        with zipfile.ZipFile(os.path.join(files, "minimal_bundles.zip")) as z:
            z.extractall(tmp)
        yield "dipy minimal bundles", trk(*sorted(glob.glob(os.path.join(tmp, "**", "*.trk"),
                                                            recursive=True)))
    try:
        cb = dipy.data.two_cingulum_bundles()
    except (OSError, ValueError) as exc:  # data missing offline
        print(f"(dipy's two cingulum bundles left out: {exc})")
        return
    yield "dipy two cingulum bundles", [np.asarray(s, dtype=float) for b in cb for s in b]


def rough_rows(repeat):
    """One ``spinal.tube`` call per set (8 sides, radius 0.1), every curve tubed: the time
    with the default round joins at sharp corners and with mitre joins, whether the mesh is
    watertight and wound outwards, its vertices, and VTK's tube filter on the same polylines
    (one PolyData; one ring per sample, no joins)."""
    import trimesh

    vtk = peers().get("pv")
    print("| set | curves | points | spinal ms (round joins) | vertices | spinal ms "
          "(join='miter') | watertight, outward | VTK strips ms | VTK vertices |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, lines in rough_sets():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            t = best(lambda ls=lines: spinal.tube(ls, 0.1, 8), repeat)
            tm_ = best(lambda ls=lines: spinal.tube(ls, 0.1, 8, join="miter"), repeat)
            m = spinal.tube(lines, 0.1, 8)
        tm = trimesh.Trimesh(m.vertices, m.faces, process=False)
        ok = tm.is_watertight and tm.is_winding_consistent and m.volume > 0
        tv = nv = "–"
        if vtk is not None:
            import pyvista as pv

            pts = np.concatenate(lines)
            cells = np.concatenate([np.r_[len(l), o + np.arange(len(l))] for l, o in
                                    zip(lines, np.r_[0, np.cumsum([len(l) for l in lines])])])
            poly = pv.PolyData(pts, lines=cells)
            tube = (lambda p=poly: p.tube(radius=0.1, n_sides=8, capping=True))
            tv = f"{1e3 * best(tube, repeat):.1f}"
            nv = f"{tube().n_points:,}"
        print(f"| {name} | {len(lines)} | {sum(len(l) for l in lines)} | {1e3 * t:.1f} | "
              f"{len(m.vertices):,} | {1e3 * tm_:.1f} | {'yes' if ok else 'NO'} | {tv} | {nv} |",
              flush=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--max", type=float, default=1e6)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--no-bundle", action="store_true",
                    help="leave out the 1,000-curve bundle row")
    ap.add_argument("--bundle", action="store_true",
                    help="add the 100,000-streamline bundle (~9.6 M points, 8 sides): spinal "
                         "float32 and VTK strips (~5 GB each)")
    ap.add_argument("--bundle-all", action="store_true",
                    help="with --bundle: also spinal float64 and VTK strips + triangulate "
                         "(~9 GB each)")
    ap.add_argument("--bundle-first", action="store_true",
                    help="with --bundle: measure first calls (the output's pages touched for "
                         "the first time), each process started 60 s after the previous one")
    ap.add_argument("--spikes", action="store_true",
                    help="only the scaling of a capped sweep of a profile with packed spikes "
                         "(star and comb, m = 10^3, 10^4, 10^5 profile vertices)")
    ap.add_argument("--rough", action="store_true",
                    help="only rough polylines: 2,000 random walks and dipy's bundled tracts")
    args = ap.parse_args()
    if args.rough:
        print(f"rough polylines tubed in one call each; ms, best of {args.repeat}\n")
        rough_rows(args.repeat)
        return
    if args.spikes:
        print(f"capped sweep of a spiky profile along a 3-point straight spine; seconds, best "
              f"of {args.repeat}\n")
        spike_rows(args.repeat)
        return
    sizes = [n for n in (1_000, 10_000, 100_000, 200_000, 1_000_000) if n <= args.max]
    rows = run(sizes, args.repeat, not args.no_bundle)
    peers_cols = ["vtk strips", "vtk strips f32", "vtk triangles", "vtk lines_from_points",
                  "trimesh sweep_polygon"]
    print("Columns: spinal = spinal.tube(points, r, sides) (float64, normals, uv, int64 faces); "
          "spinal float32 = the same with dtype=np.float32 (float32 vertices, normals, uv; "
          "int32 faces); float32 no uv = dtype=np.float32, uv=False (float32 vertices and "
          "normals, int32 faces); vtk strips = pyvista.PolyData(points, lines=[n, 0, …, n−1])"
          ".tube(radius=r, n_sides=sides, capping=True), i.e. vtkTubeFilter on one polyline "
          "per curve: triangle strips, float64 points (as the input), float32 normals, int64 "
          "connectivity; vtk strips f32 = the same on float32 points (float32 points and "
          "normals); vtk triangles = vtk strips + .triangulate() (vtkTriangleFilter); "
          "vtk lines_from_points = pyvista.lines_from_points(points).tube(...) (one line cell "
          "per segment: a capped ring pair per segment); NumPy write floor = np.full of "
          "arrays of spinal's float64 output size.\n")
    print(f"tubes with {SIDES} sides; times in ms (best of runs); ratio = peer time / spinal "
          "(float64) time; NumPy write floor: ratio = spinal / floor (target ≤ 1.4× at 1M "
          "points); the last two columns = VTK time / spinal float32 time, with the default "
          "options (targets: ≥ 3× VTK strips at 1M points, > 1× VTK triangles everywhere) and "
          "without uv against VTK on float32 points (the same outputs)\n")
    f32_col = "spinal float32: VTK strips, triangles ×"
    f32_like = "float32 no uv: VTK strips f32 ×"
    print("| case | spinal | spinal float32 | float32 no uv | NumPy write floor | "
          + " | ".join(peers_cols) + f" | {f32_col} | {f32_like} |")
    print("|---" * (7 + len(peers_cols)) + "|")
    for r in rows:
        f32, like = r["spinal float32"], r["spinal float32 no uv"]
        cells = [r["case"], f"{1e3 * r['spinal']:.1f}", f"{1e3 * f32:.1f}", f"{1e3 * like:.1f}",
                 f"{1e3 * r['floor']:.1f} ({r['spinal'] / r['floor']:.2f}×)"]
        for c in peers_cols:
            cells.append(f"{1e3 * r[c]:.1f} ({r[c] / r['spinal']:.1f}×)" if c in r else "–")
        cells.append(" / ".join(f"{r[c] / f32:.1f}" for c in ("vtk strips", "vtk triangles")
                                if c in r) or "–")
        cells.append(f"{r['vtk strips f32'] / like:.1f}" if "vtk strips f32" in r else "–")
        print("| " + " | ".join(cells) + " |")
    if args.bundle:
        first = ("the first of its size in the process (after a one-curve warm-up; started "
                 "60 s after the previous process), so its output's pages are touched for the "
                 "first time" if args.bundle_first else "after the same call once (its freed "
                 "output's pages reused)")
        print("\n100,000 streamlines × 96 points (9.6 M points), 8 sides, one call each in a fresh "
              f"process, {first}; user, system = CPU seconds of the call (all threads; system: "
              "mostly the page faults of its output); peak = VmHWM growth of the call (reset "
              "before it); numpy floor = np.full of spinal float32's output arrays\n")
        print("| call | time s | user s | system s | peak GB | output GB | peak / output | "
              "bytes per point |")
        print("|---|---|---|---|---|---|---|---|")
        for what, res, err in bundle_rows(everything=args.bundle_all, first=args.bundle_first):
            if res is None:
                print(f"| {what} | failed: {err[0][:80]} | | | | | | |")
                continue
            print(f"| {what} | {res['s']:.2f} | {res['user']:.2f} | {res['sys']:.2f} | "
                  f"{res['peak'] / 1e9:.2f} | "
                  f"{res['output'] / 1e9:.2f} | {res['peak'] / res['output']:.2f} | "
                  f"{res['peak'] / res['points']:.0f} |")


if __name__ == "__main__":
    main()
