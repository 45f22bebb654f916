"""Shared helpers: an independent reference RMF (adaptive 8th-order ODE solve) and angles."""

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

# The tests live in one folder per concept (frames, sweep, deform, ...); a test module may
# import the helpers of another concept's module by its name (`from test_deform import
# volumes`), whichever folder pytest collects first.
_HERE = os.path.dirname(os.path.abspath(__file__))
for _name in sorted(os.listdir(_HERE)):
    _dir = os.path.join(_HERE, _name)
    usable = not _name.startswith(("_", ".")) and _name != "artifacts"
    if usable and os.path.isdir(_dir) and _dir not in sys.path:
        sys.path.insert(0, _dir)

os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")


def reference_rmf(curve, u, r0, rtol=1e-13, atol=1e-15):
    """Reference vectors r(u) of the RMF from scipy's DOP853 on r' = (x'×x''/|x'|²) × r."""
    from scipy.integrate import solve_ivp

    def rhs(s, r):
        d1 = curve.d1(s)[0]
        d2 = curve.d2(s)[0]
        w = np.cross(d1, d2) / d1.dot(d1)
        return np.cross(w, r)

    sol = solve_ivp(rhs, (u[0], u[-1]), np.asarray(r0, float), method="DOP853", t_eval=u,
                    rtol=rtol, atol=atol)
    assert sol.success
    return sol.y.T


def angle_between(a, b):
    """Unsigned angle (rad) between corresponding rows of a and b."""
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.einsum("...i,...i", a, b))


def orthonormality_error(F):
    eye = np.eye(3)
    return np.abs(np.einsum("nji,njk->nik", F, F) - eye).max()


@pytest.fixture(scope="session")
def torus_knot_reference():
    """Torus knot of Wang et al. (2008) Example 1 on [0, 2π] with r0 = N(0) = (-1, 0, 0):
    parameters u (2^11 + 1 samples) and the reference r(u)."""
    from spinal.curves import TorusKnot

    k = TorusKnot()
    u = np.linspace(0, 2 * np.pi, 2**11 + 1)
    return k, u, reference_rmf(k, u, [-1.0, 0.0, 0.0])


# ------------------------------------------------------------------------- Ctrl-C

SIGINT_CHILD = """
import os, signal, sys, threading, time
import numpy as np, trimesh, spinal
from spinal import fields as fl, quaternions as Q, ph
spinal.set_num_threads(2)
# Python installs its Ctrl-C handler only when SIGINT is not ignored at start-up, and a
# shell starts background jobs with SIGINT ignored: install it here in any case
signal.signal(signal.SIGINT, signal.default_int_handler)
{setup}
sent = []
def fire():
    sent.append(time.process_time())
    os.kill(os.getpid(), signal.SIGINT)
threading.Timer({after}, fire).start()
start = time.perf_counter()
try:
    for _ in range(100):  # repeated, so a call faster than the timer is still running then
        {call}
except KeyboardInterrupt:
    # the work done after the signal: CPU time of the process (both pool threads) per
    # thread, so a machine loaded by other work does not stretch it as wall time would
    late = (time.process_time() - sent[0]) / 2
    print(f'interrupted {{late:.3f}} s of work per thread after the signal')
    sys.exit(0)
print(f'finished after {{time.perf_counter() - start:.1f}} s, no KeyboardInterrupt')
sys.exit(3)
"""


def late_after_sigint(setup: str, call: str, after: float = 0.5) -> float:
    """CPU seconds per pool thread that a child process running `call` (after `setup`)
    spends after SIGINT reaches it `after` seconds in, until KeyboardInterrupt: a measure of
    Ctrl-C latency that other load on the machine does not stretch. The child installs
    Python's SIGINT handler itself, so it also works when started with SIGINT ignored (as
    a shell starts background jobs)."""
    code = SIGINT_CHILD.format(setup=textwrap.dedent(setup), call=call, after=after)
    r = subprocess.run([sys.executable, "-c", code], check=False, capture_output=True,
                       text=True, timeout=600)
    assert r.returncode == 0, (r.returncode, r.stdout, r.stderr[-3000:])
    return float(r.stdout.split()[1])
