"""Helpers shared by the benchmark scripts: best-of-N wall time and the test spine."""

from __future__ import annotations

import time

import numpy as np


def best(f, repeat, *args, **kwargs):
    """The shortest wall time of ``repeat`` calls ``f(*args, **kwargs)``, in seconds (the
    least disturbed by other work on the machine)."""
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        f(*args, **kwargs)
        ts.append(time.perf_counter() - t0)
    return min(ts)


def helix(n, turns=100):
    """``n`` samples of the helix ``(cos u, sin u, 0.05 u)``, ``u`` over ``turns`` turns."""
    u = np.linspace(0, 2 * np.pi * turns, n)
    return np.c_[np.cos(u), np.sin(u), 0.05 * u]
