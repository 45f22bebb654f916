"""Tube throughput: spinal.tube vs VTK (PyVista ``tube``) and trimesh ``sweep_polygon``.

Same spine (a helix), same number of sides, one run. For every size it times

* ``spinal.tube(points, r, sides)`` — frames (double reflection) + mesh with normals and uv,
  float64 triangles, watertight with caps;
* VTK via PyVista on one polyline, ``PolyData.tube`` — float32 triangle strips (less output:
  no uv, strips instead of triangles); and ``+ .triangulate()`` for a triangle mesh like ours;
* VTK on ``pyvista.lines_from_points(points)`` — the call most examples show (one line per
  segment: a separate ring pair for every segment, 4× the vertices);
* ``trimesh.creation.sweep_polygon`` when shapely is installed (skipped otherwise);
* the NumPy floor: allocating and writing arrays of the size of spinal's output once.

and prints a table with the ratios. ``--bundle`` adds 1 000 curves of 1 000 points (spinal in
one call with ``lengths``; VTK one PolyData with 1 000 polylines).

    python benchmarks/bench_sweep.py              # 10^3 … 10^6 spine points
    python benchmarks/bench_sweep.py --max 2e5
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import spinal

SIDES = 16
RADIUS = 0.05


def best(f, repeat):
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        ts.append(time.perf_counter() - t0)
    return min(ts)


def helix(n, turns=100):
    u = np.linspace(0, 2 * np.pi * turns, n)
    return np.c_[np.cos(u), np.sin(u), 0.05 * u]


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
        res["floor"] = best(lambda: floor(nv, nf), rep)  # noqa: B023
        if "pv" in p:
            pv = p["pv"]
            cells = np.concatenate([np.r_[k, np.arange(k) + o]
                                    for k, o in zip(lengths, np.cumsum([0] + lengths[:-1]),
                                                    strict=True)])
            poly = pv.PolyData(x, lines=cells)
            res["vtk strips"] = best(lambda: poly.tube(radius=RADIUS, n_sides=SIDES, capping=True),  # noqa: B023
                                     rep)
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


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--max", type=float, default=1e6)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--no-bundle", action="store_true")
    args = ap.parse_args()
    sizes = [n for n in (1_000, 10_000, 100_000, 200_000, 1_000_000) if n <= args.max]
    rows = run(sizes, args.repeat, not args.no_bundle)
    peers_cols = ["vtk strips", "vtk triangles", "vtk lines_from_points", "trimesh sweep_polygon"]
    print(f"tubes with {SIDES} sides; times in ms (best of runs); ratio = peer time / spinal time\n")
    print("| case | spinal | NumPy write floor | " + " | ".join(peers_cols) + " |")
    print("|---" * (3 + len(peers_cols)) + "|")
    for r in rows:
        cells = [r["case"], f"{1e3 * r['spinal']:.1f}",
                 f"{1e3 * r['floor']:.1f} ({r['spinal'] / r['floor']:.1f}×)"]
        for c in peers_cols:
            cells.append(f"{1e3 * r[c]:.1f} ({r[c] / r['spinal']:.1f}×)" if c in r else "–")
        print("| " + " | ".join(cells) + " |")
    big = [r for r in rows if r["case"] == "200,000 points"]
    if big and "vtk lines_from_points" in big[0]:
        r = big[0]
        print(f"\n200k points × {SIDES} sides: spinal {r['vtk lines_from_points'] / r['spinal']:.1f}× "
              f"faster than VTK on lines_from_points, {r['vtk triangles'] / r['spinal']:.1f}× than "
              f"VTK strips + triangulate, {r['vtk strips'] / r['spinal']:.1f}× than VTK strips "
              f"(target ≥ 20× VTK)")


if __name__ == "__main__":
    main()
