"""One-shot fleshing against Blender's Curve modifier: the same mesh bent along the same curve.

The mesh is a tube of about 115,000 vertices around the segment x ∈ [0, 4] (1,000 rings of
115 vertices, radius 0.3); the posed spine is the quarter-turn arc of length 4 sampled at
``n`` points. spinal registers the mesh on the straight rest spine (``n`` samples) and
poses it (``spinal.flesh``, the radial solution); Blender's Curve modifier (``bpy``, run in
its own Python: ``--blender PYTHON``) deforms the mesh object along a poly curve of the
same ``n`` points. Times are the best of ``--repeat`` calls after a first call in a fresh
process (both columns), in milliseconds; the volumes show what each keeps.

    python benchmarks/bench_flesh_blender.py --blender /path/to/python-with-bpy
    python benchmarks/bench_flesh_blender.py            # spinal only
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import textwrap
import time

import numpy as np

SAMPLES = (26, 251, 1001)
RINGS, SIDES, RADIUS, LENGTH = 1000, 115, 0.3, 4.0


def shapes(n: int):
    """The mesh (vertices, faces), the straight rest spine and the arc, ``n`` samples."""
    import spinal

    x = np.linspace(0.0, LENGTH, RINGS)
    tube = spinal.tube(np.c_[x, np.zeros(RINGS), np.zeros(RINGS)], RADIUS, SIDES)
    s = np.linspace(0.0, LENGTH, n)
    rest = np.c_[s, np.zeros(n), np.zeros(n)]
    rho = LENGTH / (np.pi / 2)  # a quarter turn of length 4
    arc = np.c_[rho * np.sin(s / rho), rho * (1 - np.cos(s / rho)), np.zeros(n)]
    return tube.vertices, tube.faces, rest, arc


def volume(V, F) -> float:
    import spinal

    return float(spinal.Mesh(V, F).volume)


def spinal_times(n: int, repeat: int) -> dict:
    import spinal

    V, F, rest, arc = shapes(n)
    t0 = time.perf_counter()
    out = spinal.flesh(V, rest, arc)
    first = time.perf_counter() - t0
    warm = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        spinal.flesh(V, rest, arc)
        warm.append(time.perf_counter() - t0)
    return {"first": first, "warm": min(warm), "vertices": len(V),
            "change": volume(out, F) / volume(V, F) - 1}


BLENDER = textwrap.dedent("""
    import json, sys, time
    import numpy as np
    import bpy
    data = np.load(sys.argv[1])
    V, F, arc, repeat = data["V"], data["F"], data["arc"], int(data["repeat"])
    bpy.ops.wm.read_factory_settings(use_empty=True)
    mesh = bpy.data.meshes.new("tube")
    mesh.from_pydata(V.tolist(), [], F.tolist())
    obj = bpy.data.objects.new("tube", mesh)
    bpy.context.scene.collection.objects.link(obj)
    cu = bpy.data.curves.new("spine", "CURVE")
    cu.dimensions = "3D"
    sp = cu.splines.new("POLY")
    sp.points.add(len(arc) - 1)
    for p, x in zip(sp.points, arc):
        p.co = (float(x[0]), float(x[1]), float(x[2]), 1.0)
    cobj = bpy.data.objects.new("spine", cu)
    bpy.context.scene.collection.objects.link(cobj)
    mod = obj.modifiers.new("Curve", "CURVE")
    mod.object, mod.deform_axis = cobj, "POS_X"

    def evaluate():
        obj.update_tag()
        dg = bpy.context.evaluated_depsgraph_get()
        dg.update()
        ev = obj.evaluated_get(dg)
        m = ev.to_mesh()
        out = np.empty(len(m.vertices) * 3)
        m.vertices.foreach_get("co", out)
        ev.to_mesh_clear()
        return out.reshape(-1, 3)

    t0 = time.perf_counter()
    out = evaluate()
    first = time.perf_counter() - t0
    warm = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        evaluate()
        warm.append(time.perf_counter() - t0)
    np.save(sys.argv[2], out)
    print(json.dumps({"first": first, "warm": min(warm)}))
""")


def blender_times(python: str, n: int, repeat: int, tmp: str) -> dict:
    V, F, _, arc = shapes(n)
    src, dst = os.path.join(tmp, "in.npz"), os.path.join(tmp, "out.npy")
    np.savez(src, V=V, F=F, arc=arc, repeat=repeat)
    script = os.path.join(tmp, "curve_modifier.py")
    with open(script, "w") as f:
        f.write(BLENDER)
    r = subprocess.run([python, script, src, dst], capture_output=True, text=True, check=True)
    out = json.loads(r.stdout.strip().splitlines()[-1])
    W = np.load(dst)
    out["change"] = volume(W, F) / volume(V, F) - 1
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--blender", help="a Python interpreter with bpy (pip install bpy)")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--child", type=int, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child:
        print(json.dumps(spinal_times(a.child, a.repeat)))
        return
    import tempfile

    print(f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f}; a tube of "
          f"{RINGS * SIDES:,} vertices bent a quarter turn")
    print("| spine samples | spinal first ms | spinal warm ms | spinal ΔV/V | "
          "Blender first ms | Blender warm ms | Blender ΔV/V | warm ratio |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as tmp:
        for n in SAMPLES:
            # a fresh process each, as a one-shot call is made
            r = subprocess.run([sys.executable, __file__, "--child", str(n), "--repeat",
                                str(a.repeat)], capture_output=True, text=True, check=True)
            s = json.loads(r.stdout.strip().splitlines()[-1])
            row = (f"| {n:,} | {s['first'] * 1e3:,.0f} | {s['warm'] * 1e3:,.0f} | "
                   f"{s['change']:.1e} |")
            if a.blender:
                b = blender_times(a.blender, n, a.repeat, tmp)
                row += (f" {b['first'] * 1e3:,.0f} | {b['warm'] * 1e3:,.0f} | "
                        f"{b['change']:.1e} | {s['warm'] / b['warm']:.2f} |")
            else:
                row += " – | – | – | – |"
            print(row)


if __name__ == "__main__":
    main()
