"""Mesh measures against the build: ``Mesh.volume``, ``Mesh.area`` and ``Mesh.is_watertight``
(edge manifoldness and winding) of a tube, each timed next to the ``spinal.tube`` call that
built the mesh, and next to trimesh's ``volume`` / ``is_watertight`` on the same arrays
(``process=False``; trimesh caches, so a fresh Trimesh is timed each run) up to 10^5 points.

    python benchmarks/bench_mesh.py               # 10^4 … 10^6 spine points × 16 sides
    python benchmarks/bench_mesh.py --quick       # 10^3, 10^4
"""

from __future__ import annotations

import argparse

from _timing import best, helix

import spinal

SIDES = 16




def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--max", type=float, default=1e6, help="largest spine size")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="10^3 and 10^4 points only")
    a = ap.parse_args()
    top = 1e4 if a.quick else a.max
    sizes = [n for n in (1_000, 10_000, 100_000, 1_000_000, 10_000_000) if n <= top]
    if not a.quick:
        sizes = [n for n in sizes if n >= 10_000] or sizes
    try:
        import trimesh
    except ImportError:
        trimesh = None
    print(f"tube of a helix, {SIDES} sides, float64; best of {a.repeat}; seconds "
          f"(× the build)\n")
    print("| spine points | faces | build (tube) | volume | area | is_watertight "
          "| trimesh volume | trimesh is_watertight |")
    print("|---|---|---|---|---|---|---|---|")
    for n in sizes:
        x = helix(n)
        build = best(lambda x=x: spinal.tube(x, 0.05, SIDES), a.repeat)
        mesh = spinal.tube(x, 0.05, SIDES)
        cells = []
        for what in ("volume", "area", "is_watertight"):
            t = best(lambda w=what, m=mesh: getattr(m, w), a.repeat)
            cells.append(f"{t:.3g} ({t / build:.2f}×)")
        for what in ("volume", "is_watertight"):
            if trimesh is None or n > 100_000:
                cells.append("–")
                continue
            V, F = mesh.vertices, mesh.faces
            t = best(lambda w=what, V=V, F=F: getattr(trimesh.Trimesh(V, F, process=False), w),
                     a.repeat)
            cells.append(f"{t:.3g} ({t / build:.1f}×)")
        assert mesh.is_watertight
        print(f"| {n:,} points | {len(mesh.faces):,} | {build:.3g} | " + " | ".join(cells)
              + " |", flush=True)


if __name__ == "__main__":
    main()
