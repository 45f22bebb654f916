"""Frame throughput: spinal's methods vs the NumPy write floor (and a plain NumPy loop).

For n = 10^3 … 10^7 points on a helix it times ``spinal.frames(points)`` (tangents estimated,
the usual call) and ``spinal.frames(points, tangents)`` per method, on all cores and on one
thread (a subprocess with RAYON_NUM_THREADS=1), and divides by the time NumPy needs to
allocate and write the (n, 3, 3) float64 output once (``np.full``). A pure NumPy/Python
double-reflection loop is timed at small n as the peer a user would otherwise write.

    python benchmarks/bench_frames.py            # up to 10^7 points
    python benchmarks/bench_frames.py --max 1e6  # quicker
    python benchmarks/bench_frames.py --max 1e6 --method double_reflection --load 3

    python benchmarks/bench_frames.py --alternate 1e6 --repeat 21 --load 3

``--load N`` starts N busy-loop processes beside the whole run (both the threaded and the
one-thread measurement), to see how the threads fare when the machine has more runnable
jobs than cores; ``--method`` restricts the methods timed. Each time cell is then the best
of ``--repeat`` calls with the median in brackets. ``--alternate n`` times only
``spinal.frames`` of an n-point helix (double reflection, tangents estimated) on 1 and on 2
threads, call after call in turn, so that both see the same load from elsewhere; with
``--out`` every call writes into one array allocated (and paged in) once, ``out=``.

A second table times bundles of many short curves (``lengths=``), 10⁶ points in all (or
``--max``).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np
from _timing import best

import spinal

METHODS = ["double_reflection", "rotation", "projection", "frenet"]


@contextlib.contextmanager
def busy(n):
    """``n`` busy-loop processes running for the duration of the block."""
    procs = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(n)]
    try:
        yield
    finally:
        for p in procs:
            p.kill()
        for p in procs:
            p.wait()


def helix(n):
    u = np.linspace(0, 200 * np.pi, n)
    x = np.c_[np.cos(u), np.sin(u), 0.05 * u]
    t = np.c_[-np.sin(u), np.cos(u), np.full_like(u, 0.05)]
    return x, t


def numpy_double_reflection(x, t):
    """The loop a NumPy user writes (Table I of Wang et al.), for comparison."""
    t = t / np.linalg.norm(t, axis=1, keepdims=True)
    r = np.empty_like(x)
    r[0] = np.cross(t[0], [0.0, 0.0, 1.0])
    r[0] /= np.linalg.norm(r[0])
    for i in range(len(x) - 1):
        v1 = x[i + 1] - x[i]
        c1 = v1 @ v1
        rl = r[i] - (2 / c1) * (v1 @ r[i]) * v1
        tl = t[i] - (2 / c1) * (v1 @ t[i]) * v1
        v2 = t[i + 1] - tl
        r[i + 1] = rl - (2 / (v2 @ v2)) * (v2 @ rl) * v2
    return np.stack([r, np.cross(t, r), t], axis=2)


def best_with_floor(f, n, repeat):
    """Best times of ``f()`` and of the write floor, measured alternately in the same window
    (a burst of load from elsewhere on a shared machine then hits both alike), and the
    median time of ``f()``."""
    tf, tw = [], []
    for _ in range(repeat):
        t0 = time.perf_counter()
        np.full((n, 3, 3), 1.0)
        t1 = time.perf_counter()
        f()
        t2 = time.perf_counter()
        tw.append(t1 - t0)
        tf.append(t2 - t1)
    return min(tf), min(tw), statistics.median(tf)


def measure(sizes, repeat, methods=METHODS):
    rows = []
    for n in sizes:
        x, t = helix(n)
        rep = repeat if n < 5_000_000 else max(2, repeat // 2)
        floor = best(np.full, rep, (n, 3, 3), 1.0)
        row0 = {"n": n, "method": "numpy write floor", "tangents": "-", "s": floor,
                "floor": floor}
        rows.append(row0)
        for method in methods:
            for given in (False, True):
                args = (x, t) if given else (x,)
                s, fl, med = best_with_floor(
                    lambda a=args, m=method: spinal.frames(*a, method=m), n, rep)
                row0["s"] = row0["floor"] = min(row0["s"], fl)
                rows.append({"n": n, "method": method, "tangents": "given" if given else
                             "estimated", "s": s, "floor": fl, "median": med})
        if n <= 10_000:
            s = best(numpy_double_reflection, 1, x, t)
            rows.append({"n": n, "method": "numpy loop (DR)", "tangents": "given", "s": s,
                         "floor": row0["floor"]})
    return rows


def bundles(total, repeat):
    """A streamline bundle: ``total`` points as curves of 10, 100 and 1000 points (helix
    pieces, each shifted), in one ``spinal.frames(points, lengths=...)`` call."""
    rng = np.random.default_rng(1)
    rows = []
    for length in (10, 100, 1000):
        m = max(1, total // length)
        u = np.linspace(0, 4 * np.pi, length)
        piece = np.c_[np.cos(u), np.sin(u), 0.1 * u]
        pts = (piece[None] + rng.normal(size=(m, 1, 3))).reshape(-1, 3)
        lengths = np.full(m, length)
        s, fl, _ = best_with_floor(lambda p=pts, c=lengths: spinal.frames(p, lengths=c),
                                len(pts), repeat)
        rows.append({"curves": m, "length": length, "s": s, "floor": fl})
    return rows


def alternate(n, repeat, reuse=False):
    """Best and median times of ``spinal.frames`` on 1 and on 2 threads, called in turn
    (``reuse``: into one output array)."""
    x, _ = helix(n)
    out = np.full((n, 3, 3), 0.0) if reuse else None
    times = {1: [], 2: []}
    for _ in range(repeat):
        for threads, ts in times.items():
            with spinal.threads(threads):
                t0 = time.perf_counter()
                spinal.frames(x, out=out)
                ts.append(time.perf_counter() - t0)
    return {k: (min(v), statistics.median(v)) for k, v in times.items()}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--max", type=float, default=1e7)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--method", action="append", choices=METHODS,
                    help="time this method only (repeatable; default: all)")
    ap.add_argument("--load", type=int, default=0,
                    help="busy-loop processes to run beside the measurement")
    ap.add_argument("--alternate", type=float, default=0,
                    help="only time n points on 1 and 2 threads, call after call in turn")
    ap.add_argument("--out", action="store_true",
                    help="with --alternate: every call writes into one array (out=)")
    ap.add_argument("--json", action="store_true", help="print raw rows as JSON (internal)")
    a = ap.parse_args()
    if a.alternate:
        with busy(a.load):
            t = alternate(int(a.alternate), a.repeat, a.out)
        into = " into one out= array" if a.out else ""
        print(f"{int(a.alternate):,} points{into}, {a.load} busy processes beside, {a.repeat} calls "
              f"each: 1 thread {1e3 * t[1][0]:.1f} ms (median {1e3 * t[1][1]:.1f}), 2 threads "
              f"{1e3 * t[2][0]:.1f} ms (median {1e3 * t[2][1]:.1f}); 1 thread / 2 threads: "
              f"{t[1][0] / t[2][0]:.2f} (medians {t[1][1] / t[2][1]:.2f})")
        return
    methods = a.method or METHODS
    sizes = [n for n in (10**3, 10**4, 10**5, 10**6, 10**7) if n <= a.max]
    if a.json:
        print(json.dumps(measure(sizes, a.repeat, methods)))
        return
    with busy(a.load):
        run(a, sizes, methods)


def run(a, sizes, methods):
    rows = measure(sizes, a.repeat, methods)
    env = dict(os.environ, RAYON_NUM_THREADS="1")
    flags = [f"--method={m}" for m in methods]
    single = json.loads(subprocess.run(
        [sys.executable, __file__, "--max", str(a.max), "--repeat", str(a.repeat), "--json",
         *flags], env=env, check=True, capture_output=True, text=True).stdout)
    one = {(r["n"], r["method"], r["tangents"]): r for r in single}
    cores = os.cpu_count()
    print(f"spinal {spinal.__version__}, {cores} cores, {spinal.get_num_threads()} threads "
          f"(all), {a.load} busy processes beside; best of {a.repeat}"
          f"{' (median)' if a.load else ''}; helix samples; × write floor: against NumPy's "
          "np.full of the (n, 3, 3) output timed alternately with each call\n")
    print("| n | method | tangents | ms, 1 thread | ms, all cores | Mframes/s (all) "
          "| × write floor (all) | speed-up |")
    print("|---|---|---|---|---|---|---|---|")
    def cell(r):
        if r is None:
            return "nan"
        med = f" ({1e3 * r['median']:.3f})" if a.load and "median" in r else ""
        return f"{1e3 * r['s']:.3f}{med}"

    for r in rows:
        n, s = r["n"], r["s"]
        r1 = one.get((n, r["method"], r["tangents"]))
        s1 = r1["s"] if r1 else float("nan")
        print(f"| {n:,} | {r['method']} | {r['tangents']} | {cell(r1)} | {cell(r)} | "
              f"{n / s / 1e6:.1f} | {s / r['floor']:.2f} | {s1 / s:.2f} |")
    dr = [r for r in rows if r["n"] == 10**6 and r["method"] == "double_reflection"
          and r["tangents"] == "estimated"]
    total = int(min(a.max, 1e6))
    print(f"\nBundles of {total:,} points (double reflection, tangents estimated, all cores):\n")
    print("| curves × points | ms | ns per point | × write floor |")
    print("|---|---|---|---|")
    for r in bundles(total, a.repeat):
        pts = r["curves"] * r["length"]
        print(f"| {r['curves']:,} × {r['length']:,} | {1e3 * r['s']:.2f} | "
              f"{1e9 * r['s'] / pts:.0f} | {r['s'] / r['floor']:.2f} |")
    if dr:
        print(f"\ndouble reflection, 1M points, tangents estimated: "
              f"{dr[0]['s'] / dr[0]['floor']:.2f}× the NumPy write floor (target ≤ 4×)")


if __name__ == "__main__":
    main()
