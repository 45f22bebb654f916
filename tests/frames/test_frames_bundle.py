"""Many curves in one call, the parallel prefix scan on long curves, and GIL release."""

import os
import subprocess
import sys
import threading

import numpy as np
import pytest

import spinal
from spinal.curves import Helix, TorusKnot


def random_curves(rng, count):
    curves = []
    for _ in range(count):
        n = int(rng.integers(2, 60))
        steps = rng.normal(size=(n, 3)) * 0.1 + [1.0, 0, 0]
        curves.append(np.cumsum(steps, axis=0))
    return curves


def test_bundle_equals_separate_calls():
    rng = np.random.default_rng(5)
    curves = random_curves(rng, 40)
    flat = np.concatenate(curves)
    lengths = [len(c) for c in curves]
    for method in ("double_reflection", "rotation", "projection", "frenet"):
        F = spinal.frames(flat, method=method, lengths=lengths)
        G = np.concatenate([spinal.frames(c, method=method) for c in curves])
        np.testing.assert_array_equal(F, G)
    offsets = np.r_[0, np.cumsum(lengths)]
    np.testing.assert_array_equal(spinal.frames(flat, offsets=offsets),
                                  spinal.frames(flat, lengths=lengths))


def test_bundle_per_curve_initial_end_and_closed():
    k = TorusKnot()
    a, b = k.sample(300), k.sample(500) * 2 + 1
    flat = np.concatenate([a, b])
    init = np.array([[0.0, 0, 1], [1.0, 0, 0]])
    F = spinal.frames(flat, lengths=[300, 500], initial=init)
    np.testing.assert_array_equal(F[:300], spinal.frames(a, initial=init[0]))
    np.testing.assert_array_equal(F[300:], spinal.frames(b, initial=init[1]))
    C = spinal.frames(flat, lengths=[300, 500], closed=True)
    np.testing.assert_array_equal(C[:300], spinal.frames(a, closed=True))
    ang = spinal.closing_angle(flat, lengths=[300, 500])
    assert ang.shape == (2,)
    assert abs(ang[0] - spinal.closing_angle(a)) < 1e-15
    assert abs(ang[1] - spinal.closing_angle(k.sample(500))) < 1e-12  # similarity-invariant
    E = spinal.frames(flat, lengths=[300, 500], end=np.array([[0.0, 0, 1], [0.0, 1, 0]]))
    t = E[[299, -1], :, 2]
    for row, target, tt in zip((299, -1), ([0.0, 0, 1], [0.0, 1, 0]), t):
        p = np.array(target) - np.dot(target, tt) * tt
        np.testing.assert_allclose(E[row][:, 0], p / np.linalg.norm(p), atol=1e-12)


def test_bundle_error_names_the_curve():
    a = TorusKnot().sample(50)
    bad = a.copy()
    bad[10, 1] = np.nan
    with pytest.raises(ValueError, match=r"points: curve 1 \(rows 50 to 99\): non-finite .* "
                                         r"row 10"):
        spinal.frames(np.concatenate([a, bad]), lengths=[50, 50])
    # after a merged repeat in curve 0, an error of curve 1 names its rows as given
    rep = np.insert(a, 10, a[9], axis=0)
    with pytest.raises(ValueError, match=r"points: curve 1 \(rows 51 to 100\): non-finite .* "
                                         r"row 10"):
        spinal.frames(np.concatenate([rep, bad]), lengths=[51, 50])
    with pytest.raises(ValueError, match="lengths"):
        spinal.frames(a, lengths=[20, 20])
    with pytest.raises(ValueError, match="initial"):
        spinal.frames(np.concatenate([a, a]), lengths=[50, 50], initial=np.ones((3, 3)))


def test_long_curve_parallel_scan_matches_closed_form_and_serial():
    """A 300k-point helix is split across threads; the result must match the closed-form RMF
    and a single-threaded run (RAYON_NUM_THREADS=1 in a subprocess)."""
    h = Helix(1.0, 0.3, turns=60)
    u = h.parameters(300_001)
    x, t = h.point(u), h.tangent(u)
    exact = h.rmf(u)
    F = spinal.frames(x, t, initial=exact[0][:, 0])
    assert np.linalg.norm(F[:, :, 0] - exact[:, :, 0], axis=1).max() < 1e-10
    E = spinal.frames(x, t, initial=exact[0][:, 0], end=exact[-1][:, 1])  # twisted, split
    np.testing.assert_allclose(E[-1][:, 0], exact[-1][:, 1], atol=1e-12)
    twist = np.arctan2(np.einsum("ij,ij->i", E[:, :, 0], exact[:, :, 1]),
                       np.einsum("ij,ij->i", E[:, :, 0], exact[:, :, 0]))
    np.testing.assert_allclose(twist, np.pi / 2 * u / u[-1], atol=1e-9)  # linear in arc length
    k = TorusKnot()
    C = spinal.frames(k.sample(300_001), closed=True, initial=[-1.0, 0, 0])
    np.testing.assert_array_equal(C[-1], C[0])
    short = spinal.frames(k.sample(30_001), closed=True, initial=[-1.0, 0, 0])  # not split
    np.testing.assert_allclose(C[::10], short, atol=1e-9)
    code = (
        "import numpy as np, spinal, sys\n"
        "from spinal.curves import Helix\n"
        "h = Helix(1.0, 0.3, turns=60); u = h.parameters(300_001)\n"
        "np.save(sys.argv[1], spinal.frames(h.point(u), h.tangent(u), initial=h.rmf(u[:2])[0][:, 0]))\n"
    )
    out = os.path.join(os.environ.get("TMPDIR", "/tmp"), f"spinal_serial_{os.getpid()}.npy")
    env = dict(os.environ, RAYON_NUM_THREADS="1")
    subprocess.run([sys.executable, "-c", code, out], check=True, env=env)
    S = np.load(out)
    os.remove(out)
    assert np.abs(S - F).max() < 1e-12


def test_gil_is_released():
    h = Helix(1.0, 0.3, turns=100)
    x = h.sample(2_000_000)
    t = h.tangent(h.parameters(2_000_000))
    worker = threading.Thread(target=spinal.frames, args=(x, t), kwargs={"method": "projection"})
    count = 0
    worker.start()
    while worker.is_alive():
        count += 1
    worker.join()
    assert count > 10_000


def test_concurrent_calls_give_the_same_frames():
    """Four Python threads computing long curves at once share the two-thread pool (the
    chunks of each scan then wait on each other across busy threads): every result must be
    the one of a call made alone, bit for bit, with and without an end condition."""
    from concurrent.futures import ThreadPoolExecutor

    h = Helix(1.0, 0.3, turns=40)
    curves = [h.sample(200_000 + 3_001 * k) * (1 + 0.1 * k) for k in range(4)]
    jobs = [{"points": x} for x in curves] + [{"points": x, "end": [0.0, 0.0, 1.0]} for x in curves]
    alone = [spinal.frames(**j) for j in jobs]
    with ThreadPoolExecutor(max_workers=4) as pool:
        for _ in range(2):
            together = list(pool.map(lambda j: spinal.frames(**j), jobs))
            for a, b in zip(alone, together):
                assert np.array_equal(a, b)
