"""What ``progress=`` costs: the long calls with and without a progress callback.

With a callback, a bundle is swept (or framed) in blocks of whole curves of 2¹⁸ rows and
each block is copied into the joined output; a time series is computed in blocks of
steps. This script times, best of ``--repeat`` warm calls, each call without ``progress``
and with a callback that does nothing, and prints the ratio.

    python benchmarks/bench_progress.py              # 10,000 walks × 100 points
    python benchmarks/bench_progress.py --curves 2000 --repeat 3
"""

from __future__ import annotations

import argparse
import os
import warnings

import numpy as np
from _timing import best

import spinal


def cases(curves: int):
    rng = np.random.default_rng(0)
    walks = [np.cumsum(rng.normal(size=(100, 3)) * 0.3 + [0.5, 0, 0], 0)
             for _ in range(curves)]
    u = np.linspace(0, 40 * np.pi, 2000)
    base = np.c_[np.cos(u), np.sin(u), 0.02 * u]
    series = base + np.cumsum(rng.normal(scale=1e-3, size=(50, 2000, 3)), 0)
    rows = f"{curves * 100:,} rows"
    return [
        (f"tube, {curves:,} walks, {rows}, 8 sides, float32",
         lambda **k: spinal.tube(walks, 0.05, 8, dtype=np.float32, **k)),
        (f"frames, {curves:,} walks, {rows}", lambda **k: spinal.frames(walks, **k)),
        ("frames_in_time, 50 steps × 2,000 points",
         lambda **k: spinal.frames_in_time(series, **k)),
        ("frames_in_time(previous_twist=False), 50 × 2,000",
         lambda **k: spinal.frames_in_time(series, previous_twist=False, **k)),
    ]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--curves", type=int, default=10_000)
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    print(f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f}")
    print("| call | without progress (ms) | with a callback (ms) | ratio |")
    print("|---|---:|---:|---:|")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the walks' hairpins fold
        for name, call in cases(a.curves):
            call()  # warm
            t0 = best(call, a.repeat)
            t1 = best(call, a.repeat, progress=lambda done, total: None)
            print(f"| {name} | {t0 * 1e3:,.1f} | {t1 * 1e3:,.1f} | {t1 / t0:.2f} |")


if __name__ == "__main__":
    main()
