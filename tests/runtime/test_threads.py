"""Worker threads: ``spinal.set_num_threads``, ``spinal.threads``, ``spinal.get_num_threads``
and ``RAYON_NUM_THREADS``. The rayon pool that runs a heavy call has the number of threads
set (seen from inside the pool by ``_core.pool_threads``), results do not depend on it, the
context manager restores the previous setting, and a bad count is refused naming ``n``."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

import spinal
from spinal import _core
from spinal import fields as fl


@pytest.fixture(autouse=True)
def _default_threads():
    spinal.set_num_threads(None)
    yield
    spinal.set_num_threads(None)


def helix(n=60):
    u = np.linspace(0, 4 * np.pi, n)
    return np.c_[np.cos(u), np.sin(u), 0.2 * u]


def heavy_results():
    """Outputs of parallel calls on inputs large enough to be split across workers."""
    rng = np.random.default_rng(3)
    h = helix(20_000)
    bundle = np.concatenate([helix(500) + i for i in range(40)])
    f = spinal.frames(bundle, lengths=[500] * 40)
    tube = spinal.tube(h, 0.1, 12)
    pts = rng.normal(size=(20_000, 3)) * 0.5
    adv = spinal.advect(pts, fl.translation([0, 0, 0.3], 0.6, [0, 0, 1]), 0.2, 8)
    q = spinal.quaternions.to_quaternions(spinal.frames(h))
    return [f, tube.vertices, tube.faces, tube.normals, adv, q]


def test_results_identical_with_one_and_two_threads():
    with spinal.threads(1):
        assert _core.pool_threads() == 1
        one = heavy_results()
    with spinal.threads(2):
        assert _core.pool_threads() == 2
        two = heavy_results()
    for a, b in zip(one, two, strict=True):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("n", [1, 2, 3, 5])
def test_worker_count_is_honoured(n):
    spinal.set_num_threads(n)
    assert spinal.get_num_threads() == n
    assert _core.pool_threads() == n
    assert _core.num_threads_setting() == n


def test_default_is_back_after_none():
    default = spinal.get_num_threads()
    spinal.set_num_threads(3)
    spinal.set_num_threads(None)
    assert _core.num_threads_setting() is None
    assert spinal.get_num_threads() == default == _core.pool_threads()


def test_context_restores_previous_setting():
    default = spinal.get_num_threads()
    with spinal.threads(1):
        assert spinal.get_num_threads() == 1
        with spinal.threads(3):
            assert _core.pool_threads() == 3
        assert spinal.get_num_threads() == 1
    assert _core.num_threads_setting() is None
    assert spinal.get_num_threads() == default
    spinal.set_num_threads(2)
    with pytest.raises(RuntimeError, match="inside"), spinal.threads(1):
        assert _core.pool_threads() == 1
        raise RuntimeError("inside")
    assert _core.num_threads_setting() == 2
    with spinal.threads(None):
        assert _core.num_threads_setting() is None
    assert _core.num_threads_setting() == 2


@pytest.mark.parametrize("bad, exc", [
    (0, ValueError), (-1, ValueError), (2000, ValueError), (10**30, ValueError),
    (1.5, TypeError), (2.0, TypeError), (True, TypeError), ("2", TypeError),
    (np.float64(2), TypeError),
])
def test_bad_counts_are_named(bad, exc):
    spinal.set_num_threads(2)
    with pytest.raises(exc, match=r"^n: must be a positive int"):
        spinal.set_num_threads(bad)
    with pytest.raises(exc, match=r"^n: must be a positive int"), spinal.threads(bad):
        pass
    assert _core.num_threads_setting() == 2  # unchanged


def test_numpy_ints_are_counts():
    spinal.set_num_threads(np.int64(3))
    assert _core.pool_threads() == 3


def test_core_checks_the_range_itself():
    with pytest.raises(ValueError, match=r"^n: must be a positive int at most 1024"):
        _core.set_num_threads(0)


def counts_in_child(env: str | None, code: str = "") -> list[int]:
    environ = {k: v for k, v in os.environ.items() if k != "RAYON_NUM_THREADS"}
    if env is not None:
        environ["RAYON_NUM_THREADS"] = env
    code = ("import spinal; from spinal import _core; " + code +
            "print(spinal.get_num_threads(), _core.pool_threads())")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=environ, check=True, timeout=120).stdout
    return list(map(int, out.split()))


@pytest.mark.parametrize("env, expected", [("3", 3), ("1", 1), ("0", None), ("x", None)])
def test_rayon_num_threads_sets_the_default(env, expected):
    cpus = counts_in_child(None)  # without the variable: one thread per logical CPU
    assert cpus[0] == cpus[1] >= 1
    got = counts_in_child(env)
    assert got == [expected, expected] if expected else got == cpus
    # an explicit setting wins over the variable
    assert counts_in_child(env, "spinal.set_num_threads(2); ") == [2, 2]


def test_a_call_from_a_progress_callback_does_not_deadlock_one_thread():
    """The progress callback of advect runs on the pool's only worker; a spinal call made
    from there runs in place instead of waiting for a second worker."""
    seen = []

    def progress(done, total):
        seen.append(spinal.frames(helix()).shape)

    with spinal.threads(1):
        spinal.advect(np.zeros((10, 3)), fl.translation([0, 0, 0.3], 0.6, [0, 0, 1]), 0.1, 4,
                      progress=progress)
    assert seen and all(s == (60, 3, 3) for s in seen)


def test_long_single_curves_have_the_same_bits_on_any_thread_count():
    """T3-04: frames and closing_angle of one curve long enough for the parallel scan
    (more than 2·2^15 rows: it is cut into chunks whatever the pool size, and one thread
    scans them in turn) have the same bits on 1, 2, 3 and 5 threads, open and closed."""
    from spinal.curves import TorusKnot

    x = TorusKnot().sample(150_001)
    runs = []
    for n in (1, 2, 3, 5):
        with spinal.threads(n):
            runs.append((spinal.frames(x), spinal.frames(x, closed=True),
                         spinal.closing_angle(x), spinal.tube(x[:70_000], 0.05, 6).vertices))
    for other in runs[1:]:
        for a, b in zip(runs[0], other, strict=True):
            np.testing.assert_array_equal(a, b)


def every_concept_large():
    """One call per concept at sizes above every chunk and block threshold of the core
    (2^15 rows per frames chunk, 2^14 faces per measure block, 1 MB per sweep block, 4,096
    points per advect block, 2^12 vertices per fleshing block)."""
    import trimesh

    rng = np.random.default_rng(7)
    out = {}
    bundle = np.concatenate([helix(3_000) + i for i in range(30)])  # 90k rows
    out["frames bundle"] = spinal.frames(bundle, lengths=[3_000] * 30)
    walk = np.cumsum(rng.normal(size=(40_000, 3)), 0)  # a rough curve: joins everywhere
    t = spinal.tube(walk, 0.3, 8)
    out["tube rough"] = (t.vertices, t.faces, t.normals, t.area, t.volume)
    a = np.linspace(0, 2 * np.pi, 24, endpoint=False)
    star = np.c_[np.cos(a), np.sin(a)] * (1 + 0.3 * (np.arange(24) % 2))[:, None] * 0.05
    sw = spinal.sweep(helix(40_000), star)
    out["sweep"] = (sw.vertices, sw.faces, sw.area, sw.volume)
    field = fl.translation([0, 0, 1.2], 0.5, [0, 0, -1])
    out["advect"] = spinal.advect(rng.normal(size=(30_000, 3)) * 0.5, field, 0.5, 6)
    ico = trimesh.creation.icosphere(5)  # 10,242 vertices, 20,480 faces
    d, rep = spinal.deform(ico, field, 0.8)
    out["deform"] = (d.vertices, d.faces, rep.volume, rep.relative_change)
    rest = helix(200)
    V = rest[rng.integers(0, 200, 20_000)] + rng.normal(size=(20_000, 3)) * 0.05
    out["flesh"] = spinal.flesh(V, rest, rest * [1.1, 0.9, 1.2])
    tool = fl.mesh_curl(trimesh.creation.icosphere(3), velocity=[0, 0, 1], resolution=40)
    out["mesh_curl"] = tool(rng.normal(size=(5_000, 3)), 0.1)
    return out


@pytest.mark.filterwarnings("ignore::spinal.FoldOverWarning")  # the walk's tight bends
def test_every_concept_has_the_same_bits_on_1_2_3_and_5_threads():
    """T3-04: frames of bundles, tubes of rough curves (corner joins), profile sweeps and
    their measures, advect, deform with refinement, fleshing and a mesh tool give the same
    bits on 1, 2, 3 and 5 threads (chunk boundaries are fixed, never the pool's size)."""
    runs = []
    for n in (1, 2, 3, 5):
        with spinal.threads(n):
            runs.append(every_concept_large())
    for other in runs[1:]:
        for key, a in runs[0].items():
            b = other[key]
            for x, y in zip(a if isinstance(a, tuple) else (a,),
                            b if isinstance(b, tuple) else (b,), strict=True):
                np.testing.assert_array_equal(x, y, err_msg=key)
