"""Volume change of ``spinal.deform`` on real meshes: the analogue of Table 13.1 of Zheng's
thesis (triangles, volume before and after, for curl-field tools on scanned and CAD models).

Every case is ``spinal.deform(mesh, field, duration)`` with its defaults (default step rule,
``refine=1.5``, ``max_vertices`` = 8× the input), in a fresh process. The meshes are the
closed models of the shared test data (``../shared/data/meshes`` beside the repository, read
with ``trimesh.load(path, force="mesh")``, which merges duplicate vertices; a mesh that is not
watertight and outward wound is skipped and named), each under three tools scaled by its
bounding-box diagonal ``D``:

- **press**: a cube of side 0.12·D (``fields.mesh_curl``, resolution 64, reach 0.1·D) facing
  the mesh's flank (the side across its thinnest bounding-box axis) 0.005·D off the surface,
  moving 0.065·D into it along that axis in unit time (0.06·D deep);
- **twist**: ``fields.twist(centroid, long axis, κ, R, form="curl")``, the thesis's curl
  twist about the longest bounding-box axis through the centroid of the volume, ``R`` twice
  the largest distance of a vertex from the centroid, ``κ`` such that the largest angle a
  vertex turns is 1.5 rad;
- **rod**: a straight rod (``fields.rod``, radius 0.03·D, length 0.4·D, reach 0.06·D) lying
  along the long axis 0.005·D off the flank, turning about its centre (about the axis across
  both) in unit time by the angle that takes one end 0.06·D below the highest vertex under
  it (0.33–0.94 rad on these meshes).

And two icosphere cases: ``icosphere(4)`` under ``fields.rotation([0, 0, 0.8], 0.7, [0, 0, 1],
3.0)`` (a spinning ball turning the cap inside it by 3 rad; its tangential slip tears the
surface), and the 10,242-vertex icosphere dragged by ``fields.translation([0, 0, 0.9], 0.9,
[0.5, 0, 0])``, both for unit time.

Volumes come from trimesh and, independently, from libigl (``igl.centroid``); the script
stops when they differ by more than 1e-9 relative or differ from the report's. Crossing face
pairs of the result: ``Mesh.self_intersections`` (exact). The time is that of the
``deform`` call alone. Target: |volume change| ≤ 5e-4 with ≤ 10× the vertices. A case that
misses it is run again with 4× the steps (integration error) and on the rest mesh subdivided
once (flat-face error, expected to fall ~4× if second order), and unrefined with ``spinal.advect``
at the default and 4× steps.

    python benchmarks/bench_deform_table.py            # every case
    python benchmarks/bench_deform_table.py --quick    # the cow and a small icosphere (a smoke run)
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np

MESHES = Path(__file__).resolve().parents[2] / "shared" / "data" / "meshes"
MESH_NAMES = ("alligator", "cheburashka", "cow", "fandisk", "homer", "rocker-arm")
TOOLS = ("press", "twist", "rod")
TARGET_VOLUME, TARGET_RATIO = 5e-4, 10.0
GAP, DEPTH = 0.005, 0.06  # tool clearance at the start and depth of the press, × diagonal

# Zheng's Table 13.1 (volume before → after, triangles; C: collision, R: rotation)
THESIS = [("sphere (C)", 11200, 2.132, 2.127), ("bunny (C)", 23380, 1.997, 1.988),
          ("chess (C)", 23844, 0.576, 0.572), ("rocker-arm (C)", 43468, 0.143, 0.142),
          ("cube (R)", 33600, 8.000, 8.033), ("Venus (R)", 36396, 74.811, 74.324)]


def load(name: str, meshes: Path):
    """The closed mesh ``name`` (a file of ``meshes`` or ``icosphere(k)``) as a
    trimesh.Trimesh, or a string saying why it is skipped."""
    import trimesh

    if name.startswith("icosphere("):
        return trimesh.creation.icosphere(int(name[10:-1]))
    path = meshes / f"{name}.obj"
    if not path.exists():
        return f"{path} not found"
    m = trimesh.load(path, force="mesh")
    if not (m.is_watertight and m.is_winding_consistent and m.volume > 0):
        return (f"not a closed outward mesh (watertight {m.is_watertight}, volume "
                f"{m.volume:.3g})")
    return m


def frame(m):
    """(centroid, long axis, flank axis, diagonal): the centroid of the volume, the unit
    vectors along the longest and the shortest bounding-box side, and the box diagonal."""
    ext = m.extents
    order = np.argsort(ext)
    long_axis, flank = np.eye(3)[order[-1]], np.eye(3)[order[0]]
    return np.asarray(m.center_mass), long_axis, flank, float(np.linalg.norm(ext))


def top(V, c, flank, across, half_width):
    """The largest height (coordinate along ``flank``) of the vertices in the column over
    ``c``: those whose offsets from ``c`` along the unit vectors ``across`` are within
    ``half_width``."""
    inside = np.ones(len(V), bool)
    for a, w in zip(across, half_width, strict=True):
        inside &= np.abs((V - c) @ a) <= w
    return float((V[inside] @ flank).max())


def tool(kind: str, m):
    """(field, duration) of a tool for the mesh ``m``."""
    import trimesh

    from spinal import fields

    c, long_axis, flank, D = frame(m)
    V = np.asarray(m.vertices)
    side = np.cross(flank, long_axis)
    edge = float(m.edges_unique_length.max())
    if kind == "press":
        s = 0.12 * D
        h = top(V, c, flank, (long_axis, side), (s / 2 + edge, s / 2 + edge))
        cube = trimesh.creation.box((s, s, s))  # axis-aligned, as are the flank and long axis
        centre = c + (h - c @ flank + GAP * D + s / 2) * flank
        cube.apply_translation(centre)
        f = fields.mesh_curl(cube, velocity=-(GAP + DEPTH) * D * flank, reach=0.1 * D)
        return f, 1.0
    if kind == "twist":
        r = np.linalg.norm(V - c, axis=1)
        R = 2 * float(r.max())
        t = r / R
        z = (V - c) @ long_axis
        kappa = 1.5 / float(np.abs(z * (1 - t) * (1 - 1.5 * t)).max())
        return fields.twist(c, long_axis, kappa, R, form="curl"), 1.0
    if kind == "rod":
        rho, half = 0.03 * D, 0.2 * D
        h = top(V, c, flank, (long_axis, side), (half + rho + edge, rho + edge))
        mid = c + (h - c @ flank + GAP * D + rho) * flank
        end = mid + half * long_axis  # turning about +side takes this end down
        below = top(V, end, flank, (long_axis, side), (rho + edge, rho + edge))
        dip = (mid @ flank - rho - below + DEPTH * D) / half
        angle = float(np.arcsin(min(dip, 1.0)))
        f = fields.rod([mid - half * long_axis, end], rho, angular_velocity=angle * side,
                       pivot=mid, reach=2 * rho)
        return f, 1.0
    if kind == "cap turn":
        return fields.rotation([0, 0, 0.8], 0.7, [0, 0, 1], 3.0), 1.0
    if kind == "drag":
        return fields.translation(center=[0, 0, 0.9], radius=0.9, velocity=[0.5, 0, 0]), 1.0
    raise ValueError(f"unknown tool {kind!r}")


def volumes(V, F):
    """(trimesh, libigl) enclosed volumes."""
    import igl
    import trimesh

    V = np.ascontiguousarray(V, dtype=np.float64)
    F = np.ascontiguousarray(F, dtype=np.int64)
    return trimesh.Trimesh(V, F, process=False).volume, float(igl.centroid(V, F)[1])


def checked_change(V0, F0, W, F):
    """Rest volume, deformed volume and their relative change, by trimesh, checked against
    libigl (1e-9 relative)."""
    (a0, b0), (a, b) = volumes(V0, F0), volumes(W, F)
    for x, y in ((a0, b0), (a, b)):
        if abs(x / y - 1) > 1e-9:
            raise RuntimeError(f"trimesh and libigl volumes differ: {x!r} vs {y!r}")
    return a0, a, a / a0 - 1, max(abs(a0 / b0 - 1), abs(a / b - 1))


def run(m, f, T, steps=None):
    import spinal

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the report's converged flag says it
        clock = time.perf_counter()
        M, rep = spinal.deform(m, f, T, steps)
        return M, rep, time.perf_counter() - clock


def worker(name: str, kind: str, meshes: Path) -> dict:
    """One case in this process."""
    import trimesh

    import spinal

    m = load(name, meshes)
    if isinstance(m, str):
        return {"mesh": name, "tool": kind, "skipped": m}
    f, T = tool(kind, m)
    V, F = np.asarray(m.vertices), np.asarray(m.faces)
    M, rep, seconds = run(m, f, T)
    W, Fw = np.asarray(M.vertices), np.asarray(M.faces)
    v0, v1, change, disagree = checked_change(V, F, W, Fw)
    if abs(change - rep.relative_change) > 1e-9:
        raise RuntimeError(f"report {rep.relative_change!r} vs trimesh {change!r}")
    crossing = len(M.self_intersections())
    crossing0 = len(spinal.Mesh(V, F).self_intersections())
    out = {"mesh": name, "tool": kind, "faces": len(F), "faces_out": len(Fw), "n": len(V),
           "out": len(W), "v0": v0, "v1": v1, "change": change, "time": seconds,
           "steps": rep.steps, "converged": rep.converged, "over": rep.edges_over_threshold,
           "crossing": crossing, "crossing0": crossing0, "diag": frame(m)[3], "torn": rep.torn_vertices, "disagree": disagree,
           "moved": float(np.linalg.norm(spinal.advect(V, f, T, rep.steps) - V, axis=1).max()),
           "watertight": bool(trimesh.Trimesh(W, Fw, process=False).is_watertight)}
    if abs(change) > TARGET_VOLUME or len(W) > TARGET_RATIO * len(V) or not rep.converged:
        out["diagnosis"] = diagnose(m, f, T, rep.steps)
    return out


def diagnose(m, f, T, n: int) -> dict:
    """Relative volume changes that separate the causes of a miss: deform with 4× the steps
    (integration), deform on the rest mesh subdivided once (the flat faces between advected
    vertices: second order in the edge), and the unrefined advected mesh at n and 4n steps."""
    import trimesh

    import spinal

    V, F = np.asarray(m.vertices), np.asarray(m.faces)
    M4, rep4, _ = run(m, f, T, 4 * n)
    Vs, Fs = trimesh.remesh.subdivide(V, F)  # new vertices on the flat faces: same volume
    Ms, reps, _ = run((Vs, Fs), f, T)
    plain = [checked_change(V, F, spinal.advect(V, f, T, k), F)[2] for k in (n, 4 * n)]
    return {"steps4": rep4.relative_change, "out4": len(M4.vertices),
            "conv4": rep4.converged, "sub": reps.relative_change, "sub_n": len(Vs),
            "sub_out": len(Ms.vertices), "conv_sub": reps.converged, "plain": plain[0],
            "plain4": plain[1]}


def run_case(name: str, kind: str, meshes: Path) -> dict:
    r = subprocess.run([sys.executable, __file__, "--meshes", str(meshes), "--worker", name,
                        kind], check=True, capture_output=True, text=True)
    return json.loads(r.stdout.strip().splitlines()[-1])


def cases(quick: bool) -> list[tuple[str, str]]:
    if quick:
        return [("cow", "press"), ("cow", "twist"), ("icosphere(3)", "drag")]
    return ([(n, k) for n in MESH_NAMES for k in TOOLS]
            + [("icosphere(4)", "cap turn"), ("icosphere(5)", "drag")])


# the thesis's row beside a case of the same model and kind of motion
BESIDE = {("rocker-arm", "press"): 3, ("icosphere(5)", "drag"): 0}


def row(r: dict) -> str:
    ratio = r["out"] / r["n"]
    met = abs(r["change"]) <= TARGET_VOLUME and ratio <= TARGET_RATIO
    conv = "yes" if r["converged"] else f"no ({r['over']:,} edges over)"
    k = BESIDE.get((r["mesh"], r["tool"]))
    thesis = "–" if k is None else (
        f"{THESIS[k][0]}: {THESIS[k][3] / THESIS[k][2] - 1:+.2%}, {THESIS[k][1]:,} faces")
    return (f"| {r['mesh']} | {r['tool']} | {r['faces']:,} → {r['faces_out']:,} | "
            f"{r['v0']:.6g} | {r['v1']:.6g} | {r['change']:+.2e} | {r['time']:.2f} | "
            f"{r['n']:,} → {r['out']:,} ({ratio:.2f}×) | {conv} | {r['crossing0']:,} → "
            f"{r['crossing']:,} | {r['steps']} | {r['moved'] / r['diag']:.3f} | "
            f"{'met' if met else 'missed'} | {thesis} |")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="the cow and a small icosphere")
    ap.add_argument("--meshes", type=Path, default=MESHES, help="folder of the .obj meshes")
    ap.add_argument("--worker", nargs=2, metavar=("MESH", "TOOL"), help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.worker:
        print(json.dumps(worker(a.worker[0], a.worker[1], a.meshes)))
        return 0
    import spinal

    print(f"spinal {spinal.__version__}, {os.cpu_count()} cores; spinal.deform(mesh, field, "
          f"duration) with its defaults (refine=1.5, default steps, max_vertices = 8× input), "
          f"one run per case. Target: |volume change| ≤ {TARGET_VOLUME:g} with ≤ "
          f"{TARGET_RATIO:g}× the vertices.")
    print()
    print("| mesh | tool | faces | volume before | volume after | relative change | time s | "
          "vertices | converged | crossing pairs | steps | largest move / D | target | "
          "thesis (Table 13.1) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    results, skipped = [], {}
    for name, kind in cases(a.quick):
        if name in skipped:
            continue
        r = run_case(name, kind, a.meshes)
        if "skipped" in r:
            skipped[name] = r["skipped"]
            continue
        results.append(r)
        print(row(r), flush=True)
    print()
    for name, why in skipped.items():
        print(f"skipped {name}: {why}")
    worst = max((r["disagree"] for r in results), default=0.0)
    print(f"Volumes: trimesh; libigl's igl.centroid agrees within {worst:.1e} relative on "
          "every rest and deformed mesh. Crossing pairs: pairs of faces that cross "
          "(Mesh.self_intersections), of the rest mesh → of the result. Largest move: of an "
          "input vertex (spinal.advect at the same steps), over the bounding-box diagonal D. "
          "The time is the deform call's (wall clock, one run).")
    misses = [r for r in results if "diagnosis" in r]
    if misses:
        print()
        print("Cases missing the target (or not converged): relative volume change of "
              "deform with 4× the steps, of deform on the rest mesh subdivided once, and of "
              "the unrefined mesh (spinal.advect) at the default and 4× steps.")
        print()
        print("| mesh | tool | default | 4× steps | subdivided rest mesh | unrefined | "
              "unrefined, 4× steps |")
        print("|---|---|---|---|---|---|---|")
        for r in misses:
            d = r["diagnosis"]
            print(f"| {r['mesh']} | {r['tool']} | {r['change']:+.2e} ({r['out']:,} v) | "
                  f"{d['steps4']:+.2e} ({d['out4']:,} v) | {d['sub']:+.2e} ({d['sub_n']:,} → "
                  f"{d['sub_out']:,} v) | {d['plain']:+.2e} | {d['plain4']:+.2e} |")
    print()
    print("Zheng's thesis, Table 13.1 (C: collision, R: rotation; Xeon 2.66 GHz):")
    print()
    print("| model | triangles | volume before | volume after | relative change |")
    print("|---|---|---|---|---|")
    for model, tris, a0, a1 in THESIS:
        print(f"| {model} | {tris:,} | {a0:.3f} | {a1:.3f} | {a1 / a0 - 1:+.2%} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
