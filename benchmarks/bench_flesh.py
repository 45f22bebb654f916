"""Fleshing throughput: registration and deformation time per vertex (spinal.SpineBinding).

Setting of the thesis (Zhuo 2014 §8.5, R10): a spine of 100 samples, a mesh of 6 082
vertices; Java SE 7 on a 2.7 GHz Core i7: registration 36 ms, radial deformation 10 ms
(≈ 5.9 µs and 1.6 µs per vertex). Here: 6 082 and 10^4 … 10^6 vertices scattered around a
100-sample 3D spine (bind cost is O(vertices × samples), deform O(vertices + samples)),
each solution, single thread (``RAYON_NUM_THREADS=1`` in a child process) and all cores.
Target: ≤ 50 ns per vertex for deformation. Timings are the best of ``--repeat`` runs; on a
shared machine they are noisy.

    python benchmarks/bench_flesh.py               # up to 10^6 vertices
    python benchmarks/bench_flesh.py --quick       # smoke run (small sizes)
    python benchmarks/bench_flesh.py --volumes     # the shared meshes bent 60°: volumes
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys

import numpy as np
from _timing import best

import spinal

SAMPLES = 100



def spines():
    u = np.linspace(-1, 1, SAMPLES)
    rest = np.c_[u, 0.3 * np.sin(1.5 * u), 0.25 * np.cos(2 * u)]
    posed = np.c_[0.9 * np.sin(1.1 * u), 0.5 * (1 - np.cos(1.3 * u)), 0.3 * u**3 + 0.2 * u]
    return rest, posed


def measure(sizes, repeat):
    rest, posed = spines()
    rng = np.random.default_rng(0)
    rows = []
    for n in sizes:
        V = rest[rng.integers(5, SAMPLES - 5, n)] + rng.normal(size=(n, 3)) * 0.08
        b = spinal.SpineBinding(V, rest)
        t_bind = best(lambda V=V: spinal.SpineBinding(V, rest), max(1, repeat // 2))
        row = {"n": n, "bind": t_bind}
        for sol in ("radial", "normal", "binormal", "none"):
            row[sol] = best(lambda sol=sol, b=b: b.deform(posed, solution=sol), repeat)
        rows.append(row)
    return rows


MESHES = ("cow", "fandisk", "rocker-arm", "cheburashka", "homer")


def volume_table() -> None:
    """Each closed shared mesh bound to a straight spine along its longest principal axis
    (through the centroid, reaching past the mesh), then bent into an arc that turns 60°
    over the mesh's length: the volume change uncorrected, with the radial correction, and
    corrected then compensated to the rest volume (``spinal.compensate_volume``)."""
    import pathlib

    import trimesh

    root = pathlib.Path(__file__).resolve().parents[1] / ".." / "shared" / "data" / "meshes"
    print("| mesh | vertices | none | radial | radial + compensation | offset / size |")
    print("|---|---:|---:|---:|---:|---:|")
    for name in MESHES:
        path = root / f"{name}.obj"
        if not path.exists():
            print(f"| {name} | (not found) | | | | |")
            continue
        m = trimesh.load(path, process=False)
        V, F = np.asarray(m.vertices, dtype=float), np.asarray(m.faces)
        c = V.mean(0)
        _, _, vt = np.linalg.svd(V - c, full_matrices=False)
        axis = vt[0]
        s = (V - c) @ axis
        lo, hi = s.min() - 0.1 * np.ptp(s), s.max() + 0.1 * np.ptp(s)
        u = np.linspace(lo, hi, 201)
        rest = c + u[:, None] * axis
        side = vt[1]
        rho = (s.max() - s.min()) / (np.pi / 3)  # 60° over the mesh's length
        th = u / rho
        posed = c + (rho * np.sin(th))[:, None] * axis + (rho * (1 - np.cos(th)))[:, None] * side
        v0 = spinal.Mesh(V, F).volume
        row = []
        for sol in ("none", "radial"):
            W = spinal.flesh(V, rest, posed, solution=sol)
            row.append(spinal.Mesh(W, F).volume / v0 - 1)
        _, rep = spinal.compensate_volume((W, F), v0)
        row.append(rep.volume_after / v0 - 1)
        size = float(np.linalg.norm(np.ptp(V, axis=0)))
        print(f"| {name} | {len(V):,} | {row[0]:+.2%} | {row[1]:+.1e} | {row[2]:+.1e} | "
              f"{rep.offset / size:.1e} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--max", type=float, default=1e6, help="largest vertex count")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help="small sizes (a smoke run)")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--volumes", action="store_true",
                    help="the shared meshes bent 60°: volume change per solution")
    a = ap.parse_args()
    if a.volumes:
        volume_table()
        return
    top = 2e4 if a.quick else a.max
    sizes = [6082] + [int(s) for s in (1e4, 1e5, 1e6) if s <= top]
    repeat = 2 if a.quick else a.repeat
    if a.child:
        print(json.dumps(measure(sizes, repeat)))
        return
    runs = {}
    for label, threads in (("1 thread", "1"), ("all cores", "")):
        env = dict(os.environ)
        env.pop("RAYON_NUM_THREADS", None)
        if threads:
            env["RAYON_NUM_THREADS"] = threads
        cmd = [sys.executable, __file__, "--child", "--max", str(top), "--repeat", str(repeat)]
        out = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
        runs[label] = json.loads(out.stdout.strip().splitlines()[-1])
    print(f"cores: {os.cpu_count()}; spine: {SAMPLES} samples; thesis (Java, 2013): 6 082 "
          "vertices, bind 36 ms, radial deform 10 ms")
    print()
    print("| threads | vertices | bind ms | bind ns/v | radial ns/v | normal ns/v | "
          "binormal ns/v | none ns/v | radial ms |")
    print("|---|---|---|---|---|---|---|---|---|")
    for label, rows in runs.items():
        for r in rows:
            ns = {k: 1e9 * r[k] / r["n"] for k in ("bind", "radial", "normal", "binormal", "none")}
            print(f"| {label} | {r['n']} | {1e3 * r['bind']:.2f} | {ns['bind']:.0f} | "
                  f"{ns['radial']:.0f} | {ns['normal']:.0f} | {ns['binormal']:.0f} | "
                  f"{ns['none']:.0f} | {1e3 * r['radial']:.3f} |")


if __name__ == "__main__":
    main()
