"""Every public field constructor of ``spinal.fields`` pickles: the field comes back as the
same field (its velocities equal bit for bit at random points and times, its speed bound,
length scale and breakpoints equal), alone, in sums and keyframed, and through a process
pool started with ``spawn`` (a fresh interpreter that only has the pickle). The reference is
the field that was pickled, evaluated in this process.

The constructors are enumerated from the module, so a new constructor without an example
here, or one that does not record its call, fails."""

from __future__ import annotations

import concurrent.futures as cf
import inspect
import multiprocessing
import pickle

import numpy as np
import pytest

import spinal
from spinal import fields as fl

trimesh = pytest.importorskip("trimesh")
pytest.importorskip("igl")

C = np.array([0.1, -0.2, 0.3])
U = np.array([0.3, -1.0, 0.5])
OM = np.array([0.2, 0.5, -1.0])
TH = np.linspace(-0.6, 0.6, 7)
ARC = np.c_[np.sin(TH), 0.15 * np.sin(2 * TH), np.cos(TH)]
QUATS = np.array([[0, 0, 0, 1], [0, 0.1, 0, 1], [0.1, 0, 0.05, 1]])
QUATS /= np.linalg.norm(QUATS, axis=1)[:, None]
SPINE = np.c_[np.linspace(-0.5, 0.5, 6), 0.2 * np.sin(np.linspace(0, 2, 6)), np.zeros(6)]


def sphere_grid(h=0.05, rho=0.4, pad=0.7):
    """The signed distance to a sphere of radius ``rho`` about ``C``, sampled on a grid."""
    g = np.arange(-rho - pad, rho + pad + h / 2, h)
    X, Y, Z = np.meshgrid(g, g, g, indexing="ij")
    return np.sqrt(X**2 + Y**2 + Z**2) - rho, C + g[0]


D, O = sphere_grid()
MESH = trimesh.creation.icosphere(2, radius=0.4)
MESH.apply_translation(C)


def examples():
    """One or more calls per public constructor (keyword options varied)."""
    sph = fl.translation(C, 0.4, U, reach=0.3)
    return {
        "translation": [sph, fl.translation(C, 0.3, U, falloff_power=4, moving=False)],
        "rotation": [fl.rotation(C, 0.3, [0, 0, 1], 1.5, pivot=C + 0.2, reach=0.25)],
        "twist": [fl.twist(C, [0, 1, 0], 2.0, 0.8), fl.twist(C, [0, 0, 1], 1.0, 0.5, form="curl")],
        "bend": [fl.bend(C, [1, 0, 0], 1.5, 0.7)],
        "sphere": [fl.sphere(C, 0.3, U, reach=0.2, blend="linear")],
        "capsule": [fl.capsule(C, C + [0.5, 0, 0], 0.2, U, moving=False)],
        "strip": [fl.strip(C, C + [1, 0, 0], 0.2, [0.7, 0, 0]),
                  fl.strip(C, C + [1, 0, 0], 0.2, [0, 0.7, 0], kind="across")],
        "torus": [fl.torus(C, [0, 0, 1], 0.8, 0.2, 1.2, reach=0.3)],
        "strip_curve": [fl.strip_curve(ARC, 0.1, 1.3, reach=0.1)],
        "sdf_tool": [fl.sdf_tool(D, O, 0.05, U, reach=0.3)],
        "mesh_tool": [fl.mesh_tool(MESH, U, reach=0.3, resolution=32)],
        "sdf_curl": [fl.sdf_curl(D, O, 0.05, angular_velocity=OM, reach=0.3, falloff_power=3)],
        "mesh_curl": [fl.mesh_curl(MESH, velocity=U, reach=0.3, resolution=32)],
        "rod": [fl.rod(ARC, 0.15, angular_velocity=OM, pivot=C, reach=0.2)],
        "along_path": [fl.along_path(SPINE, 0.2, 1.0, kind="rotate", rate=0.5),
                       fl.along_path(SPINE, 0.2, 1.0, tool="carry", t0=0.2)],
        "keyframed": [fl.keyframed(sph, [0, 0.4, 1.0], [C, C + U * 0.2, C + 0.5],
                                   QUATS)],
    }


def constructors():
    """The public functions of spinal.fields that return a Field (``sum`` combines them)."""
    return {n for n in fl.__all__
            if inspect.isfunction(getattr(fl, n)) and n != "sum"}


def points_and_times(seed=0, n=3000):
    rng = np.random.default_rng(seed)
    return C + rng.uniform(-1.2, 1.2, (n, 3)), rng.uniform(-0.1, 1.1, 5)


def same_field(a, b):
    x, ts = points_and_times()
    for t in (0.0, *ts):
        assert np.array_equal(a(x, t), b(x, t)), t
    assert a.max_speed == b.max_speed and a.length_scale == b.length_scale
    assert np.array_equal(a.breakpoints(), b.breakpoints())
    assert len(a) == len(b) and repr(a) == repr(b)


def test_every_public_constructor_has_an_example():
    assert set(examples()) == constructors()


@pytest.mark.parametrize("name", sorted(constructors()))
def test_each_constructor_round_trips(name):
    for f in examples()[name]:
        x, _ = points_and_times()
        assert np.abs(f(x, 0.3)).max() > 0  # the example moves something
        for protocol in range(2, pickle.HIGHEST_PROTOCOL + 1):
            same_field(pickle.loads(pickle.dumps(f, protocol=protocol)), f)


def test_sums_round_trip_with_every_term():
    made = [f for fs in examples().values() for f in fs]
    total = fl.sum(made)
    back = pickle.loads(pickle.dumps(total))
    same_field(back, total)
    assert len(back) == len(made)
    # each term counts: dropping any one changes the sum's velocities
    x, _ = points_and_times(1, 500)
    for i in range(len(made)):
        rest = fl.sum(made[:i] + made[i + 1:])
        assert not np.array_equal(rest(x, 0.3), back(x, 0.3)), made[i]
    a = made[0] + made[8]  # the builtin sum and + keep the recipe too
    same_field(pickle.loads(pickle.dumps(a)), a)
    s = sum(made[:3])
    same_field(pickle.loads(pickle.dumps(s)), s)


def test_keyframed_tools_of_each_shape_round_trip():
    shapes = [fl.rotation(C, 0.3, [0, 0, 1], 1.0), fl.sdf_curl(D, O, 0.05, velocity=U, reach=0.3),
              fl.mesh_curl(MESH, velocity=U, reach=0.3, resolution=32),
              fl.rod(ARC[[0, -1]], 0.15, velocity=U), fl.sdf_tool(D, O, 0.05, U, reach=0.3),
              fl.mesh_tool(MESH, U, reach=0.3, resolution=32)]
    for tool in shapes:
        k = fl.keyframed(tool, [0, 0.5, 1.0], [C, C + [0.2, 0, 0], C + [0.3, 0.1, 0]],
                         falloff_power=4)
        same_field(pickle.loads(pickle.dumps(k)), k)
        kk = fl.keyframed(k, [0, 1.0], [C, C - [0, 0, 0.2]])
        same_field(pickle.loads(pickle.dumps(kk)), kk)


def test_an_unrecorded_field_refuses_to_pickle():
    """A field built by the core without a recorded call cannot be rebuilt: pickling it is
    an error, not the zero field."""
    raw = spinal._core.field_translation(C, 0.3, U, None, 2, True)
    with pytest.raises(pickle.PicklingError, match="translation"):
        pickle.dumps(raw)
    with pytest.raises(pickle.PicklingError):
        pickle.dumps(fl.sphere(C, 0.3, U) + raw)
    assert len(pickle.loads(pickle.dumps(fl.sum([])))) == 0


def advect_in_worker(field, x, duration):
    return spinal.advect(x, field, duration)


def test_a_field_goes_through_a_spawned_process_pool():
    made = examples()
    field = made["strip_curve"][0] + made["sdf_curl"][0] + made["along_path"][0]
    x, _ = points_and_times(2, 400)
    want = spinal.advect(x, field, 0.5)
    ctx = multiprocessing.get_context("spawn")
    with cf.ProcessPoolExecutor(1, mp_context=ctx) as pool:
        got = pool.submit(advect_in_worker, field, x, 0.5).result(timeout=300)
    assert np.array_equal(got, want)
    assert not np.array_equal(want, x)
