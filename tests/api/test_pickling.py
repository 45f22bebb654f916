"""Every exception and warning class of spinal survives pickling with its attributes, so a
process pool (``concurrent.futures``, Dask, joblib) can send it back from a worker, raised
or recorded. ``FoldOverWarning`` carries ``indices`` beyond its message."""

from __future__ import annotations

import concurrent.futures as cf
import inspect
import multiprocessing
import pickle
import warnings

import numpy as np
import pytest

import spinal


def circle(r, n):
    a = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.c_[r * np.cos(a), r * np.sin(a), np.zeros(n)]


def exception_classes():
    """The exception and warning classes spinal defines, found in every public module."""
    mods = [spinal, spinal.curves, spinal.fields, spinal.ph, spinal.quaternions]
    found = {}
    for mod in mods:
        for name in dir(mod):
            obj = getattr(mod, name)
            if (inspect.isclass(obj) and issubclass(obj, BaseException)
                    and obj.__module__.startswith("spinal")):
                found[obj.__qualname__] = obj
    return found


def instance(cls):
    """An instance with every ``__init__`` argument set to something recognisable."""
    if cls is spinal.FoldOverWarning:
        return cls("spine rows 3–5 fold over", np.array([3, 4, 5]), np.array([0, 0, 1]),
                   np.array([3, 4, 0]))
    if cls is spinal.SkippedCurvesWarning:
        return cls("curves 2, 7 left out", np.array([2, 7]))
    if cls is spinal.PrecisionWarning:
        return cls("float32 cannot resolve the profile", 0.0625, 3.9e-5)
    return cls(f"a {cls.__name__}")


def same(a, b):
    assert type(a) is type(b)
    assert a.args == b.args and str(a) == str(b)
    assert a.__dict__.keys() == b.__dict__.keys()
    for k, v in a.__dict__.items():
        np.testing.assert_array_equal(v, b.__dict__[k])


def test_the_known_classes_are_found():
    assert {"FoldOverWarning", "RefinementWarning"} <= exception_classes().keys()


@pytest.mark.parametrize("cls", exception_classes().values(), ids=lambda c: c.__name__)
@pytest.mark.parametrize("protocol", range(pickle.HIGHEST_PROTOCOL + 1))
def test_round_trip_keeps_attributes(cls, protocol):
    e = instance(cls)
    e.extra = "set after construction"
    back = pickle.loads(pickle.dumps(e, protocol=protocol))
    same(e, back)
    assert back.extra == "set after construction"


def test_a_real_fold_over_warning_round_trips():
    with pytest.warns(spinal.FoldOverWarning) as rec:
        spinal.tube(circle(0.5, 40), 0.6, 8, closed=True)
    w = rec[0].message
    back = pickle.loads(pickle.dumps(w))
    same(w, back)
    np.testing.assert_array_equal(back.indices, np.arange(40))


# ------------------------------------------------------------------ through a process pool


def raise_fold_over(r):
    with warnings.catch_warnings():
        warnings.simplefilter("error", spinal.FoldOverWarning)
        return spinal.tube(circle(0.5, 40), r, 8, closed=True).volume


def record_warnings(r):
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        spinal.tube(circle(0.5, 40), r, 8, closed=True)
    return [w.message for w in rec]


def raise_each(name):
    raise instance(exception_classes()[name])


@pytest.mark.parametrize("method", ["fork", "spawn"])
def test_process_pool_sends_them_back(method):
    spinal.tube(circle(0.5, 40), 0.3, 8, closed=True)  # the parent's pools exist (fork)
    ctx = multiprocessing.get_context(method)
    with cf.ProcessPoolExecutor(2, mp_context=ctx) as pool:
        fine = pool.submit(raise_fold_over, 0.3)
        folded = pool.submit(raise_fold_over, 0.6)
        recorded = pool.submit(record_warnings, 0.6)
        each = {n: pool.submit(raise_each, n) for n in exception_classes()}
        assert fine.result(timeout=120) > 0
        e = folded.exception(timeout=120)
        assert isinstance(e, spinal.FoldOverWarning)
        np.testing.assert_array_equal(e.indices, np.arange(40))
        (w,) = recorded.result(timeout=120)
        assert isinstance(w, spinal.FoldOverWarning)
        np.testing.assert_array_equal(w.indices, np.arange(40))
        for name, f in each.items():
            same(f.exception(timeout=120), instance(exception_classes()[name]))


def sweep_meshes():
    """Meshes of tube and sweep as returned, lazy attributes untouched."""
    rng = np.random.default_rng(5)
    walks = [np.cumsum(rng.normal(size=(m, 3)), axis=0) for m in (5, 9, 14)]
    star = [(np.cos(a) * r, np.sin(a) * r) for a, r in
            zip(np.linspace(0, 2 * np.pi, 10, endpoint=False), [1, 0.45] * 5)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", spinal.FoldOverWarning)
        return {
            "tube": spinal.tube(walks[2], 0.1, 8),
            "bundle": spinal.tube(walks, 0.1, 6, point_data={"c": np.arange(3.0)}),
            "closed seams": spinal.tube(circle(1, 30), 0.1, 6, closed=True, split_seams=True),
            "merged rows": spinal.tube(np.r_[walks[1][:4], walks[1][3:]], 0.1, 6),
            "sweep": spinal.sweep(walks[2], star, scale=0.05),
            "float32": spinal.tube(walks, 0.1, 6, dtype=np.float32),
        }


def mesh_arrays(m):
    return {k: getattr(m, k) for k in ("vertices", "faces", "normals", "uv", "fold_over",
                                       "sample_of", "curve_of", "skipped_curves")}


def check_same_mesh(a, b):
    for k, v in mesh_arrays(a).items():
        w = getattr(b, k)
        assert (v is None) == (w is None), k
        if v is not None:
            assert v.dtype == w.dtype and np.array_equal(v, w), k
    assert a.point_data.keys() == b.point_data.keys()
    for k in a.point_data:
        np.testing.assert_array_equal(a.point_data[k], b.point_data[k])
    np.testing.assert_array_equal(a.cell_data.get("curve_id"), b.cell_data.get("curve_id"))


def test_sweep_meshes_pickle_as_returned():
    """T3-03: meshes of tube and sweep pickle before any lazy attribute (sample_of,
    curve_of, curve ids) is read, and come back equal, also from a spawned process pool."""
    meshes = sweep_meshes()
    for name, m in meshes.items():
        for protocol in range(2, pickle.HIGHEST_PROTOCOL + 1):
            back = pickle.loads(pickle.dumps(m, protocol=protocol))
            check_same_mesh(back, sweep_meshes()[name])
    ctx = multiprocessing.get_context("spawn")
    with cf.ProcessPoolExecutor(1, mp_context=ctx) as pool:
        sent = pool.submit(sweep_meshes).result(timeout=300)
    for name, m in sweep_meshes().items():
        check_same_mesh(sent[name], m)
