"""A randomized harness on the input validation of ``frames`` and ``sweep``: random shapes,
dtypes, NaN/inf/huge/tiny/empty arrays and random keyword arguments. Every call returns
finite arrays of the right shape or raises ValueError/TypeError whose message starts with
the name of an argument; never another exception type, never a crash.

Runs for ``SPINAL_FUZZ_SECONDS`` seconds (default 10 per function) from the seed
``SPINAL_FUZZ_SEED`` (default: a fixed one; the failing case's seed and call are printed).
"""

import os
import re
import time
import warnings

import numpy as np
import pytest

import spinal

# numpy casts of random input; fuzzing runs for SPINAL_FUZZ_SECONDS
pytestmark = [pytest.mark.filterwarnings("ignore"), pytest.mark.slow]

SECONDS = float(os.environ.get("SPINAL_FUZZ_SECONDS", "10"))
SEED = int(os.environ.get("SPINAL_FUZZ_SEED", "20261202"))

VALUES = [0.0, 1.0, -1.0, 0.5, np.nan, np.inf, -np.inf, 1e300, -1e300, 1e-300, 5e-324, 1e150,
          1e-150, 2.0**70]
DTYPES = [np.float64, np.float32, np.int64, np.int8, np.uint8, np.bool_, np.complex128, object,
          str]


def smooth(rng, n):
    u = np.linspace(0, rng.uniform(0.5, 12), n)
    x = np.c_[np.cos(u), np.sin(u), rng.uniform(-0.5, 0.5) * u]
    return x * 10.0 ** rng.integers(-200, 200) + rng.normal(size=3) * rng.choice([0, 1, 1e9])


def rand_array(rng, like=None):
    """A random array: often a valid curve, else random shape/dtype/values."""
    r = rng.random()
    if like is not None and r < 0.35:
        a = like.copy()
        if rng.random() < 0.5 and a.size:
            a.flat[rng.integers(a.size)] = VALUES[rng.integers(len(VALUES))]
        return a
    shape = [(), (0,), (3,), (0, 3), (1, 3), (2, 3), (5, 3), (7, 2), (4, 3, 3), (3, 3), (6, 4),
             (2, 2, 2, 2)][rng.integers(12)]
    vals = rng.choice(VALUES, size=shape) if rng.random() < 0.3 else rng.normal(size=shape)
    dt = DTYPES[rng.integers(len(DTYPES))] if rng.random() < 0.3 else np.float64
    try:
        out = np.asarray(vals).astype(dt)
    except (ValueError, OverflowError):
        out = np.asarray(vals)
    if rng.random() < 0.1:
        return out.tolist()
    if rng.random() < 0.05:
        return "abc"
    return out


def rand_scalar(rng, kind):
    r = rng.random()
    if r < 0.5:
        return kind(rng)
    return [None, True, 0, -1, 3, 2**70, -2**70, 1.5, np.nan, np.inf, "x", [1, 2], np.array(2.0),
            np.int64(2), 1e300][rng.integers(15)]


ARGS = {"points", "tangents", "method", "initial", "closed", "end", "turns", "reflection", "u",
        "lengths", "offsets", "profile", "frames", "scale", "twist", "caps", "profile_closed",
        "miter_limit", "split_seams", "strict", "radius", "sides", "constraints", "twist_rule",
        "guide", "guide_weight", "guide_tolerance", "previous", "tangent_rule", "dtype",
        "normals", "uv", "point_data", "on_short", "previous_twist"}
# an argument, or an element of one ("points[3]: ..." for a curve of a list)
NAMED = re.compile(r"^([a-z_]+)(\[\d+\])?(, [a-z_]+)*:")


def check(call, expect_shape):
    """Run ``call``; return None or the unexpected outcome."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            out = call()
    except (ValueError, TypeError) as e:
        m = NAMED.match(str(e))
        names = re.sub(r"\[\d+\]", "", m.group(0)).rstrip(":").split(", ") if m else []
        if not m or not set(names) <= ARGS:
            return f"{type(e).__name__} not naming an argument: {e}"
        return None
    except Exception as e:  # noqa: BLE001 - any other type is the failure we look for
        return f"{type(e).__name__}: {e}"
    arr = out.vertices if isinstance(out, spinal.Mesh) else out
    if not np.isfinite(arr).all():
        return "non-finite output"
    if expect_shape is not None and arr.shape != expect_shape:
        return f"shape {arr.shape}, expected {expect_shape}"
    return None


def frames_case(rng):
    n = int(rng.integers(2, 12))
    x = smooth(rng, n)
    pts = x if rng.random() < 0.5 else rand_array(rng, x)
    kw = {}
    if rng.random() < 0.3:
        kw["tangents"] = rand_array(rng, np.gradient(x, axis=0))
    for name, gen in [
        ("method", lambda r: ["double_reflection", "rotation", "projection", "frenet", "rk4",
                              "bogus"][r.integers(6)]),
        ("initial", lambda r: rand_array(r, np.array([0.3, -0.2, 0.9]))),
        ("closed", lambda r: bool(r.random() < 0.5)),
        ("end", lambda r: rand_array(r, np.array([1.0, 0, 0]))),
        ("turns", lambda r: int(r.integers(-3, 4))),
        ("reflection", lambda r: ["chord", "tangents"][r.integers(2)]),
        ("lengths", lambda r: np.array([n // 2, n - n // 2])),
    ]:
        if rng.random() < 0.25:
            kw[name] = rand_scalar(rng, gen)
    shape = None
    if isinstance(pts, np.ndarray) and pts.ndim == 2 and pts.shape[1] == 3:
        shape = (len(pts), 3, 3)
    return (lambda: spinal.frames(pts, **kw)), shape, (pts, kw)


def default_frames(x):
    try:
        return spinal.frames(x)
    except ValueError:  # a random curve whose points coincide in float64
        return np.tile(np.eye(3), (len(x), 1, 1))


def sweep_case(rng):
    n = int(rng.integers(2, 10))
    x = smooth(rng, n)
    s = float(np.abs(x).max()) or 1.0
    prof = 0.01 * s * np.array([[1, 0], [0, 1], [-1, 0], [0, -1.0]])
    pts = x if rng.random() < 0.6 else rand_array(rng, x)
    kw = {}
    for name, gen in [
        ("frames", lambda r: rand_array(r, default_frames(x))),
        ("scale", lambda r: rand_array(r, np.ones(n))),
        ("twist", lambda r: rand_array(r, np.zeros(n))),
        ("closed", lambda r: bool(r.random() < 0.5)),
        ("caps", lambda r: bool(r.random() < 0.5)),
        ("profile_closed", lambda r: bool(r.random() < 0.5)),
        ("miter_limit", lambda r: float(r.uniform(0.5, 8))),
        ("split_seams", lambda r: bool(r.random() < 0.5)),
        ("strict", lambda r: False),
        ("lengths", lambda r: np.array([n // 2, n - n // 2])),
    ]:
        if rng.random() < 0.2:
            kw[name] = rand_scalar(rng, gen)
    profile = prof if rng.random() < 0.7 else rand_array(rng, prof)
    if rng.random() < 0.2:
        return ((lambda: spinal.tube(pts, rand_scalar(rng, lambda r: 0.01 * s),
                                     rand_scalar(rng, lambda r: int(r.integers(3, 9))))),
                None, (pts, "tube"))
    return (lambda: spinal.sweep(pts, profile, **kw)), None, (pts, profile, kw)


@pytest.mark.parametrize("case", [frames_case, sweep_case], ids=["frames", "sweep"])
def test_random_input_gives_an_answer_or_a_named_error(case):
    rng = np.random.default_rng([SEED, case is sweep_case])
    end = time.monotonic() + SECONDS
    calls = 0
    while time.monotonic() < end:
        call, shape, what = case(rng)
        problem = check(call, shape)
        assert problem is None, f"call {calls} (seed {SEED}): {problem}\ninput: {what!r}"[:3000]
        calls += 1
    assert calls > 50
