"""Shared helpers: an independent reference RMF (adaptive 8th-order ODE solve) and angles."""

import os

import numpy as np
import pytest

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
