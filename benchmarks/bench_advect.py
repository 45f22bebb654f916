"""Advection throughput: ns per vertex per RK4 step, spinal (Rust) vs NumPy on the same field.

For each field (curl translation of a moving sphere, von Funck's sphere ∇p × ∇q, a twist) and
each size (an icosphere of 40,962 vertices and about 1M random points in the same region)
it times ``spinal.advect(V, field, T, steps)`` on one thread (``RAYON_NUM_THREADS=1`` in a
subprocess) and on all cores, and a NumPy RK4 of the same closed-form field (vectorised over
vertices, 4 field evaluations per step). The NumPy result is checked against spinal's. The
last column is the share of points inside the field's support at t = 0 (points outside cost
a few multiplications: the translation tools are local, the twist moves every point).
Our target: ≤ 30 ns/vertex/step. A second table times the fields without a NumPy
counterpart: the strip along a curved axis (a closest-point solve per evaluation) and a
distance-grid tool (a 64-node tricubic B-spline, 64 coefficients per evaluation), and the
curl tools of any shape (rod, sdf_curl, mesh_curl, a keyframed rod; target ≤ 60 ns).

    python benchmarks/bench_advect.py            # 40,962 and 1,000,000 vertices
    python benchmarks/bench_advect.py --max 1e5  # small sizes only
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
from spinal import fields

STEPS = 16
T = 0.3


def cases():
    return {
        "curl translation": (fields.translation([0, 0, 1.32], 0.3, [0, 0, -1]), np_translation),
        "sphere ∇p×∇q": (fields.sphere([0, 0, 0.9], 0.3, [1, 0, 0], reach=0.6, moving=False),
                         np_sphere),
        "twist": (fields.twist([0, 0, 0], [0, 0, 1], 4.0, 2.0), np_twist),
    }


def tool_cases():
    th = np.linspace(-0.6, 0.6, 13)
    axis = np.c_[np.sin(th), 0.15 * np.sin(2 * th), np.cos(th)]
    # the sphere of "sphere ∇p×∇q" as a sampled distance, spaced as mesh_tool's default grid
    h = (0.6 + 1.2) / 55
    ax = np.arange(-0.9 - 4 * h, 0.9 + 4.5 * h, h)
    g = np.linalg.norm(np.stack(np.meshgrid(ax, ax, ax, indexing="ij"), -1), axis=-1) - 0.3
    out = {
        "strip along a curved axis": fields.strip_curve(axis, 0.3, 1.0, reach=0.3),
        f"distance-grid tool ({len(ax)}³)": fields.sdf_tool(g, np.array([0, 0, 0.9]) + ax[0], h,
                                                           [1, 0, 0], reach=0.6, moving=False),
    }
    return out | curl_tool_cases(axis, g, ax, h)


def curl_tool_cases(axis, g, ax, h):
    """The curl tools of any shape: a rod on the strip's axis pressing in, the sampled sphere
    (and a 2,562-vertex sphere mesh sampled by mesh_curl's default 64-node grid) as curl
    translations, and the rod following keys along a curve while turning."""
    import trimesh

    rod = fields.rod(axis, 0.3, velocity=[0, 0, -1], reach=0.3)
    s = trimesh.creation.icosphere(4)
    times = np.linspace(0, T, 5)
    mid = axis.mean(axis=0)
    keys = mid + np.c_[0.3 * np.sin(4 * times), 0 * times, -times]
    turn = np.c_[0 * times, 1.5 * times, 0 * times]
    from scipy.spatial.transform import Rotation

    return {
        "rod curl tool (curved axis)": rod,
        f"sdf_curl ({len(ax)}³)": fields.sdf_curl(g, np.array([0, 0, 0.9]) + ax[0], h,
                                                  velocity=[1, 0, 0], reach=0.6, moving=False),
        "mesh_curl (2,562-vertex sphere)": fields.mesh_curl(
            (0.3 * s.vertices + [0, 0, 0.9], s.faces), velocity=[1, 0, 0], reach=0.6,
            moving=False),
        "keyframed rod (5 keys, turning)": fields.keyframed(
            fields.rod(axis, 0.3, velocity=[0, 0, -1], reach=0.3, center=mid), times, keys,
            Rotation.from_rotvec(turn).as_matrix()),
    }


# ---- NumPy versions of the same fields -----------------------------------------------------

def np_translation(x, t):
    u = np.array([0.0, 0, -1])
    c = np.array([0, 0, 1.32]) + u * t
    rho, R = 0.3, 0.3
    y = x - c
    r = np.sqrt(np.einsum("ij,ij->i", y, y))
    d = r - rho
    e = np.clip(R - np.abs(d), 0, None)
    n = y / r[:, None]
    sg = np.where(d < 0, -1.0, 1.0)
    return (e / R**2)[:, None] * (e[:, None] * u + sg[:, None] * ((n @ u)[:, None] * y
                                                                  - r[:, None] * u))


def np_sphere(x, t):
    u = np.array([1.0, 0, 0])
    y = x - np.array([0, 0, 0.9])
    r = np.sqrt(np.einsum("ij,ij->i", y, y))
    s = np.clip((r - 0.3) / 0.6, 0, 1)
    g = 1 - s**3 * (4 - 3 * s)
    db = 12 * s**2 * (1 - s) / 0.6
    n = y / r[:, None]
    return (g * g)[:, None] * u + (g * db)[:, None] * ((n @ u)[:, None] * y - r[:, None] * u)


def np_twist(x, t):
    r = np.sqrt(np.einsum("ij,ij->i", x, x))
    h = 4.0 * x[:, 2] * np.clip(1 - r / 2.0, 0, None) ** 2
    return h[:, None] * np.c_[-x[:, 1], x[:, 0], np.zeros(len(x))]


def np_rk4(v, x, T, n):
    h = T / n
    for k in range(n):
        t = k * h
        k1 = v(x, t)
        k2 = v(x + h / 2 * k1, t + h / 2)
        k3 = v(x + h / 2 * k2, t + h / 2)
        k4 = v(x + h * k3, t + h)
        x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return x


# ---- timing ----------------------------------------------------------------------------------

def points(n):
    if n == 40962:
        import trimesh

        return np.ascontiguousarray(trimesh.creation.icosphere(6).vertices, dtype=np.float64)
    rng = np.random.default_rng(0)
    d = rng.normal(size=(n, 3))
    return d / np.linalg.norm(d, axis=1)[:, None] * rng.random(n)[:, None] ** (1 / 3)



def time_spinal(n, repeat):
    V = points(n)
    out = {}
    every = {name: f for name, (f, _) in cases().items()} | tool_cases()
    for name, f in every.items():
        spinal.advect(V[:1000], f, T, STEPS)  # warm-up
        out[name] = best(lambda f=f: spinal.advect(V, f, T, STEPS), repeat) / (n * STEPS) * 1e9
    return out


def progress_cost(repeat):
    """``advect(progress=callable)`` against the same call without: one core call either way,
    in blocks of about 20 ms; with a callable, each block reports the multiples of 1/100 of
    the steps that it passed."""
    V = points(40962)
    name, f = next((k, v) for k, v in tool_cases().items() if k.startswith("distance-grid"))
    plain = best(lambda: spinal.advect(V, f, T, 100), repeat)
    prog = best(lambda: spinal.advect(V, f, T, 100, progress=lambda done, total: None), repeat)
    print(f"\nadvect(progress=callable), {name}, 40,962 vertices, 100 steps: "
          f"{prog / plain:.2f}× the call without ({plain * 1e3:.0f} ms)")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--max", type=float, default=1e6)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--worker", type=int, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.worker:
        print(json.dumps(time_spinal(a.worker, a.repeat)))
        return
    sizes = [n for n in (40962, 1_000_000) if n <= a.max]
    print(f"RK4, {STEPS} steps, ns per vertex per step (4 field evaluations); "
          f"{os.cpu_count()} cores. Numbers are noisy on a shared machine.\n")
    print(f"| field | vertices | spinal 1 thread | spinal {os.cpu_count()} threads | NumPy "
          f"| NumPy / spinal (all) | max |Δ| vs NumPy | moving at t=0 |")
    print("|---|---|---|---|---|---|---|---|")
    tools = []
    for n in sizes:
        env = dict(os.environ, RAYON_NUM_THREADS="1")
        one = json.loads(subprocess.run([sys.executable, __file__, "--worker", str(n),
                                         "--repeat", str(a.repeat)], env=env, check=True,
                                        capture_output=True, text=True).stdout)
        allc = time_spinal(n, a.repeat)
        V = points(n)
        for name, (f, npf) in cases().items():
            reps = max(1, a.repeat if n < 2e5 else 1)
            t_np = best(lambda npf=npf, V=V: np_rk4(npf, V, T, STEPS), reps) / (n * STEPS) * 1e9
            diff = np.abs(np_rk4(npf, V[:5000], T, STEPS)
                          - spinal.advect(V[:5000], f, T, STEPS)).max()
            moving = (np.abs(f(V)).max(axis=1) > 0).mean()
            print(f"| {name} | {n:,} | {one[name]:.1f} | {allc[name]:.1f} | {t_np:.0f} | "
                  f"{t_np / allc[name]:.0f}× | {diff:.1e} | {moving:.0%} |")
        tools.append((n, one, allc, V))
    print(f"\n| field (no NumPy version) | vertices | spinal 1 thread | spinal {os.cpu_count()} "
          f"threads | moving at t=0 |")
    print("|---|---|---|---|---|")
    for n, one, allc, V in tools:
        for name, f in tool_cases().items():
            moving = (np.abs(f(V)).max(axis=1) > 0).mean()
            print(f"| {name} | {n:,} | {one[name]:.1f} | {allc[name]:.1f} | {moving:.0%} |")
    progress_cost(a.repeat)


if __name__ == "__main__":
    main()
