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
