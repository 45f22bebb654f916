"""The curl tools of any shape and the keyframed tools, tool by motion: spinal.fields.rod,
sdf_curl, mesh_curl and keyframed, each translating (``velocity=``; for keyframed: keys
with positions only) and turning (``angular_velocity=``, ``pivot=``; for keyframed: keys with
orientations), each with a divergence test, an RK4 order test and the volume of a
40,962-vertex icosphere split into integration and mesh error. The cells that
tests/deform/test_deform_curl.py already covers are not repeated here:

=============  ============================  ===============================  ==========
tool, motion   divergence                    RK4 order                        40k volume
=============  ============================  ===============================  ==========
rod T          curl file (steady); here      curl file (capsule); here a      curl file
               moving, t > 0                 curved rod
rod R          curl file (steady); here      here                             here
               moving, t > 0
sdf_curl T     curl file                     curl file (sampled sphere);      here
                                             here smooth samples
sdf_curl R     curl file                     here                             here
mesh_curl T    curl file                     here                             here
mesh_curl R    here                          here                             here
keyframed T    here (rod, sampled torus;     here (rod, 3 keys)               here
               mid-interval)
keyframed R    curl file (at a key); here    here (rod, 3 keys)               here
               mid-interval (rod, torus)
=============  ============================  ===============================  ==========

Independent references: central-difference divergence, the distances of the tools from
SciPy's spline axis (rods) and libigl (meshes), the keyframed poses from SciPy's Hermite
spline and slerp, convergence orders measured against 4096-step runs, and mesh volumes
from trimesh and libigl.
"""

from __future__ import annotations

import igl
import igl.predicates
import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp
from test_deform import icosphere, volumes
from test_deform_curl import (
    ARC,
    AXIS,
    OM,
    RHO,
    R,
    ball,
    bessel_hermite,
    divergence_ok,
    rk4_ratios,
    rod_distance,
    rod_points,
)
from test_deform_tools import C, sphere_grid, torus_mesh

import spinal
from spinal import fields

pytestmark = pytest.mark.slow  # a matrix of grid tools

CEN = ARC.mean(axis=0)  # the keyframed rod's centre
KEY_TIMES = np.array([0.0, 0.4, 1.0])
KEY_POS = CEN + np.array([[0, 0, 0], [0.1, 0.2, -0.1], [0.3, 0.1, -0.3]])
KEY_ROT = Rotation.from_rotvec([[0, 0, 0], [0.2, 0.4, -0.1], [0.5, 0.3, 0.3]])


def turn(om, t):
    """The rotation by |Ω| t about Ω/|Ω|."""
    return Rotation.from_rotvec(np.asarray(om, float) * t)


class KeyPose:
    """The pose of a keyframed tool at time t from SciPy: the centre on the Hermite spline
    with Bessel tangents, the orientation by slerp (None: no orientations)."""

    def __init__(self, times, pos, rot=None, centre=CEN):
        self.cs, self.centre = bessel_hermite(times, pos), centre
        self.slerp = None if rot is None else Slerp(times, rot)

    def q(self, t):
        return Rotation.identity() if self.slerp is None else self.slerp([t])[0]

    def to_world(self, x, t):
        """Rest-pose points x carried to the pose at t."""
        return self.cs(t) + self.q(t).apply(x - self.centre)

    def to_body(self, x, t):
        return self.centre + self.q(t).inv().apply(x - self.cs(t))


def torus_grid(h=0.025, major=0.3, minor=0.1, reach=0.3, pad=6):
    """The exact signed distance of a torus about the z axis, sampled about the origin."""
    half = major + minor + reach + pad * h
    ax = np.arange(-half, half + h / 2, h)
    g = np.stack(np.meshgrid(ax, ax, ax, indexing="ij"), -1)
    return np.sqrt((np.hypot(g[..., 0], g[..., 1]) - major) ** 2 + g[..., 2] ** 2) - minor, -half


# ---- divergence: the cells not covered by test_every_new_tool_is_divergence_free ------------

PIVOT = np.array([0.2, 0.1, 0.5])


def test_moving_rods_are_divergence_free_at_their_current_pose():
    """The rod translated by u t and turned by |Ω| t about the pivot (moving=True): the rest
    sample points of the curl file carried along with the tool."""
    x = rod_points()
    u = np.array([0.3, -1.0, 0.5])
    for p in (2, 4):
        f = fields.rod(ARC, RHO, velocity=u, reach=R, falloff_power=p)
        assert divergence_ok(f, x + 0.3 * u, R, t=0.3)
        g = fields.rod(ARC, RHO, angular_velocity=OM, pivot=PIVOT, reach=R, falloff_power=p)
        assert divergence_ok(g, PIVOT + turn(OM, 0.3).apply(x - PIVOT), R, t=0.3)


def test_a_turning_mesh_curl_tool_is_divergence_free():
    """A torus mesh turning about an off-centre pivot, steady and at a turned pose; points
    5e-3 off its surface and its support edge (libigl's distance at the pose)."""
    V, F = torus_mesh()
    pivot = C + [0.3, -0.1, 0.2]
    y = ball(C, 0.8, 20000, seed=3)
    for moving, t in ((False, 0.0), (True, 0.0), (True, 0.35)):
        f = fields.mesh_curl((V, F), angular_velocity=OM, pivot=pivot, reach=0.2, moving=moving)
        body = pivot + turn(OM, -t).apply(y - pivot) if moving else y
        d = igl.signed_distance(body, V, F)[0]
        xs = y[(np.abs(d) > 5e-3) & (np.abs(d) < 0.2 - 5e-3)]
        assert len(xs) > 3000
        assert divergence_ok(f, xs, 0.2, t)


@pytest.mark.parametrize("turning", [False, True], ids=["translation", "rotation"])
@pytest.mark.parametrize("t", [0.15, 0.55, 0.9])
def test_a_keyframed_rod_is_divergence_free_between_the_keys(turning, t):
    """Three keys (with an orientation change for ``rotation``), at times inside the key
    intervals, where ċ and ω are interpolated (not a key's): the rest sample points carried
    to SciPy's pose at t."""
    base = fields.rod(ARC, RHO, velocity=[0, 0, 1], reach=R, center=CEN)
    rot = KEY_ROT if turning else None
    kf = fields.keyframed(base, KEY_TIMES, KEY_POS, None if rot is None else rot.as_matrix())
    pose = KeyPose(KEY_TIMES, KEY_POS, rot)
    assert divergence_ok(kf, pose.to_world(rod_points(), t), R, t)


def torus_distance(x, major=0.3, minor=0.1):
    return np.sqrt((np.hypot(x[:, 0], x[:, 1]) - major) ** 2 + x[:, 2] ** 2) - minor


@pytest.mark.parametrize("turning", [False, True], ids=["translation", "rotation"])
def test_a_keyframed_sampled_torus_is_divergence_free_between_the_keys(turning):
    """The same keys and times with an sdf_curl shape (a sampled torus centred at C, which
    has no symmetry about the keys' turns): points 2e-3 off its surface and support edge
    (the exact torus distance at SciPy's pose)."""
    d, o = torus_grid()
    base = fields.sdf_curl(d, o + C, 0.025, velocity=[0, 0, 1], center=C, reach=0.3)
    rot = KEY_ROT if turning else None
    pos = KEY_POS - CEN + C
    kf = fields.keyframed(base, KEY_TIMES, pos, None if rot is None else rot.as_matrix())
    pose = KeyPose(KEY_TIMES, pos, rot, centre=C)
    for t in (0.15, 0.55, 0.9):
        y = ball(pose.cs(t), 0.8, 8000, seed=8)
        dt = torus_distance(pose.to_body(y, t) - C)
        xs = y[(np.abs(dt) > 2e-3) & (np.abs(dt) < 0.3 - 2e-3)]
        assert len(xs) > 2000
        assert divergence_ok(kf, xs, 0.3, t)


# ---- RK4 order -------------------------------------------------------------------------------

def smooth_paths(f, x, T, keep, t0=0.0):
    """The points whose path lines satisfy ``keep(W, t)`` at 17 times over [t0, t0 + T]."""
    ok, W = keep(x, t0), x
    for k in range(16):
        W = spinal.advect(W, f, T / 16, 8, t0=t0 + T * k / 16)
        ok &= keep(W, t0 + T * (k + 1) / 16)
    return x[ok]


def off_the_rod(body, gap=0.03, end=0.02):
    """Outside the rod by ``gap`` (at the pose ``body(W, t)`` maps back from) and with the
    foot point ``end`` inside the axis: away from the tool surface, the end planes (where the
    distance is only C¹) and the axis inside the tool (where ∇d is singular)."""
    def keep(W, t):
        d, u = rod_distance(body(W, t))
        return (d > gap) & (u > end) & (u < AXIS.s[-1] - end)
    return keep


U_ROD = np.array([0.2, -0.3, -1.0])
OM_ROD = np.array([0.5, 1.5, -0.4])
PIVOT_ROD = CEN + [0.1, 0.2, 0.0]


@pytest.mark.parametrize("kind", ["rod-translation", "rod-rotation", "keyframed-translation",
                                  "keyframed-rotation"])
def test_rk4_is_fourth_order_on_rods_and_keyframed_rods(kind):
    """falloff_power=4 (C² at the support edge); moving tools; path lines that stay 0.03 off
    the rod (at its pose), and off its end planes, crossing the normal planes at the axis'
    samples (where the clamped spline's third derivative jumps: no measurable loss). The
    keyframed rod runs from t0 = 0.1 to 0.8, inside the first and last key intervals, across
    the key at 0.4 (a breakpoint: ċ's slope and ω jump there). Measured against a 4096-step
    run at 16 … 256 steps (8 → 16 is not yet asymptotic for the keyframed rod: 10.0×):
    14.3–17.3× per halving (~1,000 path lines each)."""
    t0, T = 0.0, 0.2
    if kind == "rod-translation":
        f = fields.rod(ARC, RHO, velocity=U_ROD, reach=0.25, falloff_power=4)
        body = lambda W, t: W - U_ROD * t
    elif kind == "rod-rotation":
        f = fields.rod(ARC, RHO, angular_velocity=OM_ROD, pivot=PIVOT_ROD, reach=0.25,
                       falloff_power=4)
        body = lambda W, t: PIVOT_ROD + turn(OM_ROD, -t).apply(W - PIVOT_ROD)
    else:
        rot = KEY_ROT if kind == "keyframed-rotation" else None
        base = fields.rod(ARC, RHO, velocity=[0, 0, 1], reach=0.25, falloff_power=4, center=CEN)
        f = fields.keyframed(base, KEY_TIMES, KEY_POS, None if rot is None else rot.as_matrix())
        np.testing.assert_array_equal(f.breakpoints(), KEY_TIMES)
        body = KeyPose(KEY_TIMES, KEY_POS, rot).to_body
        t0, T = 0.1, 0.7
    x0 = CEN if t0 == 0 else KeyPose(KEY_TIMES, KEY_POS).cs(t0)
    x = smooth_paths(f, ball(x0, 0.45, 1500, seed=5), T, off_the_rod(body), t0)
    assert len(x) > 300
    assert (np.linalg.norm(f(x, t0), axis=1) > 0.1).sum() > 100  # the points do move
    ratios = rk4_ratios(f, x, T, t0, steps=(16, 32, 64, 128, 256))
    assert np.all((ratios > 13.5) & (ratios < 18.5)), ratios


def outside_sphere(centre_at, rho=0.4, gap=0.03):
    """Outside the sphere of radius rho about ``centre_at(t)`` by ``gap``."""
    return lambda W, t: np.linalg.norm(W - centre_at(t), axis=1) - rho > gap


OM_GRID = np.array([0.3, 1.0, -0.5])
PIVOT_GRID = C + [0.15, 0.0, 0.1]


def grid_motion(kind):
    """Keyword arguments and the tool centre's path for a grid tool centred at C."""
    if kind == "translation":
        return {"velocity": [1.0, 0, 0]}, lambda t: C + [t, 0, 0]
    return ({"angular_velocity": OM_GRID, "pivot": PIVOT_GRID},
            lambda t: PIVOT_GRID + turn(OM_GRID, t).apply(C - PIVOT_GRID))


def quadric_grid(h=0.05, rho=0.4, half=1.2):
    """Samples of the smooth level-set function ``(|X − C|² − ρ²)/(2ρ)`` (not a distance;
    |∇| = 1 on the sphere |X − C| = ρ), 10 cells beyond the support of reach 0.3: the
    natural-spline interpolant reproduces the quadric in the support up to the end
    conditions' effect, which decays by 2 − √3 per cell (~2e-6)."""
    ax = np.arange(-half, half + h / 2, h)
    g = np.stack(np.meshgrid(ax, ax, ax, indexing="ij"), -1)
    return ((g**2).sum(-1) - rho**2) / (2 * rho), C - half, h


@pytest.mark.parametrize("kind", ["translation", "rotation"])
def test_rk4_is_fourth_order_on_sdf_curl_with_smooth_samples(kind):
    """With samples whose interpolant is smooth (a quadric) a moving or turning sdf_curl
    tool (falloff_power=4) keeps RK4's order: measured 16.0–16.3× per halving at 8 … 128
    steps (path lines 0.03 outside the tool). On sampled distances the interpolant is only C²
    (its third derivatives jump across cell faces), the field C¹, and RK4 is third order
    (test_rk4_is_third_order_on_sampled_distances)."""
    kw, centre_at = grid_motion(kind)
    d, o, h = quadric_grid()
    f = fields.sdf_curl(d, o, h, reach=0.3, falloff_power=4, **kw)
    x = smooth_paths(f, ball(C, 0.8, 1500, seed=6), 0.2, outside_sphere(centre_at))
    assert len(x) > 1000
    ratios = rk4_ratios(f, x, 0.2)
    assert np.all((ratios > 15) & (ratios < 17)), ratios


def point_orders(f, x, T, steps=(16, 32, 64, 128, 256), ref_steps=4096):
    """Per halving: the ratio of the largest errors and the median per-point order (of the
    points whose error at the coarsest steps is above 1e-3 of the largest)."""
    ref = spinal.advect(x, f, T, ref_steps)
    E = np.array([np.linalg.norm(spinal.advect(x, f, T, n) - ref, axis=1) for n in steps])
    big = E[0] > 1e-3 * E[0].max()
    return E.max(1)[:-1] / E.max(1)[1:], np.median(np.log2(E[:-1, big] / E[1:, big]), axis=1)


@pytest.mark.parametrize("tool, kind", [("sdf_curl", "rotation"), ("mesh_curl", "translation"),
                                        ("mesh_curl", "rotation")])
def test_rk4_is_third_order_on_sampled_distances(tool, kind):
    """A sampled sphere (ρ 0.4, spacing 0.025) and a 2,562-vertex sphere mesh (libigl's
    distance on the 64-node grid, spacing 0.025), falloff_power=4, moving: the C²
    interpolant's third derivatives jump across the cell faces the path lines cross, so each
    crossing step errs by O(h³) and RK4 is third order (a fixed number of crossings per path
    line). Measured at 16 … 256 steps against 4096: the median per-point order 2.9–3.5,
    2.99–3.08 at the finest halving. The largest error is a noisy measure here (other
    points take the lead as the error falls, grazing crossings of cell faces among them):
    3.3–25× per halving, 1,840–6,190× over the four halvings (order 2.7–3.15). Asserted:
    median order 2.8–3.7 on each halving and 2.8–3.3 on the last; the largest error falls
    more than 1,000× (order 2.5) over the four."""
    kw, centre_at = grid_motion(kind)
    if tool == "sdf_curl":
        d, o = sphere_grid(0.025, reach=0.3)
        f = fields.sdf_curl(d, o, 0.025, reach=0.3, falloff_power=4, **kw)
    else:
        S, G = icosphere(4)
        f = fields.mesh_curl((0.4 * S + C, G), reach=0.3, falloff_power=4, **kw)
    x = smooth_paths(f, ball(C, 0.8, 1500, seed=7), 0.2, outside_sphere(centre_at))
    assert len(x) > 1000
    ratios, orders = point_orders(f, x, 0.2)
    assert np.prod(ratios) > 1000 and np.all((orders > 2.8) & (orders < 3.7)), (ratios, orders)
    assert 2.8 < orders[-1] < 3.3, orders


# ---- the volume of a 40k icosphere: integration and mesh error -------------------------------

TH_V = np.linspace(-0.5, 0.5, 7)
ARC_V = np.c_[np.sin(TH_V), 0.2 * np.sin(2 * TH_V), np.cos(TH_V)] * 1.3  # 0.15 above the sphere
TOP = np.array([0.0, 0.0, 1.2])  # a tool centre 0.2 above the unit sphere's pole
SPIN = [2.0, 0.5, 0.5]  # about a tilted axis: the tori turn off their symmetry axis


def volume_case(kind):
    """(field, t0, duration) of a tool deforming the unit sphere; no material is inside a
    tool at the start."""
    if kind == "rod-rotation":  # the curved rod turning about its centre, its ends dipping in
        return fields.rod(ARC_V, 0.15, angular_velocity=[0, 1.0, 0], reach=0.3), 0.0, 0.3
    if kind.startswith("sdf_curl"):
        if kind.endswith("translation"):  # a sampled sphere pressing 0.15 in
            d, o = sphere_grid(0.025, rho=0.3, reach=0.3)
            o = o - C + [0, 0, 1.35]
            return fields.sdf_curl(d, o, 0.025, velocity=[0, 0, -1], reach=0.3), 0.0, 0.2
        d, o = torus_grid()  # a sampled torus spinning above the pole
        return fields.sdf_curl(d, o + TOP, 0.025, angular_velocity=SPIN, reach=0.3), 0.0, 0.3
    if kind.startswith("mesh_curl"):
        V, F = torus_mesh()  # a torus mesh (major 0.35, minor 0.15) pressing 0.05 in / spinning
        V = V - C + TOP + [0, 0, 0.05]
        if kind.endswith("translation"):
            return fields.mesh_curl((V, F), velocity=[0, 0, -1], reach=0.3), 0.0, 0.15
        return fields.mesh_curl((V, F), angular_velocity=SPIN, reach=0.3), 0.0, 0.3
    # the curved rod on three keys, pressing in (and turning), from and to mid-interval times
    cen = ARC_V.mean(axis=0)
    base = fields.rod(ARC_V, 0.15, velocity=[0, 0, -1], reach=0.3, center=cen)
    pos = cen + np.array([[0, 0, 0], [0.05, 0, -0.1], [0.1, 0.05, -0.3]])
    rot = Rotation.from_rotvec([[0, 0, 0], [0, 0, 0.3], [0.1, 0.05, 0.6]]).as_matrix()
    kf = fields.keyframed(base, [0.0, 0.1, 0.3], pos, rot if kind.endswith("rotation") else None)
    return kf, 0.05, 0.2


@pytest.mark.parametrize("kind", ["rod-rotation", "sdf_curl-translation", "sdf_curl-rotation",
                                  "mesh_curl-translation", "mesh_curl-rotation",
                                  "keyframed-translation", "keyframed-rotation"])
def test_volume_of_a_40k_icosphere_integration_and_mesh_error(kind):
    """Default steps on the 40,962-vertex unit icosphere (rod-translation: the curl file).
    A 4×-steps run stands for the exact flow: the integration error is the volume change
    between the two, the mesh error the volume change of the reference (the polyhedron
    through exact-flow points is not the image of the polyhedron). The mesh error is second
    order in the edge length: on the 10,242-vertex icosphere it is ~4× (measured 3.93–4.09,
    asserted 3.7–4.3; the torus mesh pressing 0.1 in instead of 0.05 gives 3.59, and 3.97
    between 40,962 and 163,842 vertices: the 10k mesh does not yet resolve that dent).
    Measured total (= the mesh error within 0.2 %): rod turning 9.10e-6, sampled sphere
    pressing 1.92e-5, sampled torus spinning 1.03e-5, torus mesh pressing 2.13e-5 and
    spinning 1.49e-5, keyframed rod 4.28e-5 (positions only) and 3.48e-5 (turning);
    integration errors 1.9e-11 … 2.5e-8, 1,700–540,000× below the mesh error."""
    f, t0, T = volume_case(kind)
    n = f.steps(T)
    mesh = []
    for k in (6, 5):
        V, F = icosphere(k)
        ref = spinal.advect(V, f, T, 4 * n, t0=t0)
        (v0t, v0i), (vrt, vri) = volumes(V, F), volumes(ref, F)
        assert abs(v0t / v0i - 1) < 1e-12 and abs(vrt / vri - 1) < 1e-12  # trimesh = libigl
        mesh.append(vrt / v0t - 1)
        if k == 6:
            assert len(V) == 40962
            W = spinal.advect(V, f, T, t0=t0)  # default steps
            vt, vi = volumes(W, F)
            assert abs(vt / vi - 1) < 1e-12
            total, integration = vt / v0t - 1, vt / vrt - 1
            assert abs(total) <= 7e-5, total
            assert abs(integration) < 1e-7 and abs(integration) < abs(mesh[0]) / 100, (
                integration, mesh[0])
            assert np.linalg.norm(W - V, axis=1).max() > 0.1  # the mesh did deform
            assert not igl.predicates.find_self_intersections(W, F, first_only=True)[0]
    assert 3.7 < mesh[1] / mesh[0] < 4.3, mesh
