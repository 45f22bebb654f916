"""Peak memory of the compiled part of the frames calls, in bytes a row, output included: the
numbers behind ``WORKING_BYTES_PER_ROW`` in src/frames/mod.rs (the bound that the bindings check
is free before a frames call). Linux only.

Every configuration runs in a fresh process whose ``spinal._core`` functions are wrapped: the
peak resident set (VmHWM) is reset through ``/proc/self/clear_refs`` just before the compiled
call, and its peak less the resident set at the start, divided by the rows, is printed; so is
the growth of the address space (VmPeak over VmSize at the start) where the call reached a new
peak of it (the bindings' own probe, freed at once, is part of that figure).

    python benchmarks/memory_frames.py                   # 4·10^6 rows, every configuration
    python benchmarks/memory_frames.py --rows 1e7 guide+constraints_closed frenet
"""

from __future__ import annotations

import argparse
import subprocess
import sys

CHILD = r"""
import types
import numpy as np, spinal
from spinal import quaternions as Q, _core
spinal.set_num_threads(2)
u = np.linspace(0, 4 * np.pi, 60); H = np.c_[np.cos(u), np.sin(u), .2 * u]
spinal.frames(H); spinal.frames(H[:29] * [1, 1, 0], closed=True)  # the pool and its arenas

def status(key):
    for line in open('/proc/self/status'):
        if line.startswith(key):
            return int(line.split()[1]) * 1024

seen = []

class Measured(types.ModuleType):
    def __getattr__(self, name):
        f = getattr(_core, name)
        if not callable(f):
            return f
        def call(*a, **k):
            with open('/proc/self/clear_refs', 'w') as c:
                c.write('5')
            rss, size, peak = status('VmRSS'), status('VmSize'), status('VmPeak')
            r = f(*a, **k)
            hwm, peak2 = status('VmHWM'), status('VmPeak')
            seen.append((name, hwm - rss, peak2 - size if peak2 > peak else None))
            return r
        return call

import spinal._frames, spinal._frames_time, spinal.quaternions
spinal._frames._core = spinal._frames_time._core = Measured('measured')
spinal.quaternions._core = spinal._frames._core
n = {n}
# the inputs written in place (no temporaries of their size)
s = np.linspace(0, 1000 * np.pi, n, endpoint=False)
X = np.empty((n, 3)); np.cos(s, out=X[:, 0]); np.sin(s, out=X[:, 1])
np.sin(3 * s, out=X[:, 2]); X[:, 2] *= .3
T = np.empty((n, 3)); np.sin(s, out=T[:, 0]); T[:, 0] *= -1; np.cos(s, out=T[:, 1])
np.cos(3 * s, out=T[:, 2]); T[:, 2] *= .9
P = spinal.frames(X, closed=True) if {previous} else None
PT = np.stack([X, X * 1.01]) if {steps} > 1 else None
seen.clear()
{call}
rows = n * {steps}
for name, resident, space in seen:
    if resident > rows:
        print(f"{{name}}: {{resident / rows:.1f}} B/row resident"
              + ("" if space is None else f", {{space / rows:.1f}} B/row address space"))
"""

# name: (the call, previous frames needed, time steps)
CASES = {
    "open": ("spinal.frames(X)", False, 1),
    "open_end": ("spinal.frames(X, end=[0, 0, 1])", False, 1),
    "closed": ("spinal.frames(X, closed=True)", False, 1),
    "given_tangents_closed": ("spinal.frames(X, T, closed=True)", False, 1),
    "given_tangents_open": ("spinal.frames(X, T)", False, 1),
    "frenet": ("spinal.frames(X, method='frenet')", False, 1),
    "projection_closed": ("spinal.frames(X, method='projection', closed=True)", False, 1),
    "rotation_closed": ("spinal.frames(X, method='rotation', closed=True)", False, 1),
    "bundle": ("spinal.frames(X, lengths=[1000] * (n // 1000))", False, 1),
    "bundle_frenet": ("spinal.frames(X, lengths=[1000] * (n // 1000), method='frenet')", False, 1),
    "constraints": ("spinal.frames(X, constraints={n // 2: [0, 0, 1]})", False, 1),
    "constraints_closed": ("spinal.frames(X, closed=True, constraints={n // 2: [0, 0, 1]})",
                           False, 1),
    "min_angular_speed": (("spinal.frames(X, closed=True, twist_rule='min_angular_speed', "
                          "constraints={n // 2: [0, 0, 1]})"), False, 1),
    "guide": ("spinal.frames(X, guide=[0, 0, 1])", False, 1),
    "guide_closed": ("spinal.frames(X, guide=[0, 0, 1], closed=True)", False, 1),
    "guide_per_row_closed": ("spinal.frames(X, guide=X, closed=True)", False, 1),
    "guide+constraints_closed": (("spinal.frames(X, guide=[0, 0, 1], closed=True, "
                                 "constraints={n // 2: [0, 0, 1]})"), False, 1),
    "previous": ("spinal.frames(X, closed=True, previous=P)", True, 1),
    "analytic": ("spinal.frames(spinal.curves.Helix(), u=np.linspace(0, 1, n))", False, 1),
    "analytic_rk4": (("spinal.frames(spinal.curves.Helix(), u=np.linspace(0, 1, n), "
                     "method='rk4')"), False, 1),
    "analytic_guide": (("spinal.frames(spinal.curves.Helix(), u=np.linspace(0, 1, n), "
                       "guide=[0, 0, 1])"), False, 1),
    "frames_in_time": ("spinal.frames_in_time(PT, closed=True)", False, 2),
    "frames_in_time_frenet": ("spinal.frames_in_time(PT, method='frenet')", False, 2),
    "quaternion_frames": ("Q.quaternion_frames(X)", False, 1),
}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rows", type=float, default=4e6, help="rows of the curve")
    ap.add_argument("cases", nargs="*", help=f"some of: {', '.join(CASES)}")
    a = ap.parse_args()
    n = int(a.rows)
    for name in a.cases or list(CASES):
        call, previous, steps = CASES[name]
        code = CHILD.format(n=n, call=call, previous=previous, steps=steps)
        r = subprocess.run([sys.executable, "-c", code], check=False, capture_output=True,
                           text=True)
        out = " | ".join(r.stdout.split("\n")).strip(" |") or r.stderr.strip()[-300:]
        print(f"{name:26s} {out}", flush=True)


if __name__ == "__main__":
    main()
