"""The default tangent rule's end tangents: 4th order on fine samplings, and never leaning
from the end chord by more than half the turn of the last two chords (from a turn of 20° on;
the whole turn up to 10°) nor more than 45° on coarse ones; tangents of bundles
(lengths=/offsets=)."""

import numpy as np
import pytest

import spinal


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _angle(a, b):
    return np.arccos(np.clip((_unit(a) * _unit(b)).sum(-1), -1.0, 1.0))


def _end_lean_and_turn(pts, t):
    """(angle of each end tangent to its end chord, turn between the end chord and the next),
    first end then last end, for curves stacked as (C, n, 3)."""
    c0, c1 = pts[:, 1] - pts[:, 0], pts[:, 2] - pts[:, 1]
    d0, d1 = pts[:, -1] - pts[:, -2], pts[:, -2] - pts[:, -3]
    lean = np.r_[_angle(t[:, 0], c0), _angle(t[:, -1], d0)]
    turn = np.r_[_angle(c0, c1), _angle(d0, d1)]
    return lean, turn


def _cone(turn):
    """The end cone's half-angle for end chords turning by ``turn``: the whole turn up to 10°,
    half of it from 20° on (a smoothstep between), at most 45°."""
    lo, hi = np.radians(10), np.radians(20)
    s = np.clip((turn - lo) / (hi - lo), 0, 1)
    return np.minimum(turn * (1 - 0.5 * s * s * (3 - 2 * s)), np.pi / 4)


def _helix(u):
    return np.c_[np.cos(u), np.sin(u), 0.5 * u]


def _helix_t(u):
    return _unit(np.c_[-np.sin(u), np.cos(u), np.full_like(u, 0.5)])


def _wiggle(u):
    # varying curvature and torsion, unevenly sampled below
    return np.c_[u + 0.3 * np.sin(2 * u), np.cos(u) + 0.2 * u**2, 0.4 * np.sin(3 * u)]


def _wiggle_t(u):
    return _unit(np.c_[1 + 0.6 * np.cos(2 * u), -np.sin(u) + 0.4 * u, 1.2 * np.cos(3 * u)])


@pytest.mark.parametrize("curve", ["helix", "wiggle"])
def test_end_tangents_fourth_order_on_fine_samplings(curve):
    f, ft = (_helix, _helix_t) if curve == "helix" else (_wiggle, _wiggle_t)
    errs = []
    ns = [40, 80, 160, 320]
    for n in ns:
        s = np.linspace(0, 1, n)
        u = 2.0 * (s + 0.15 * s * (1 - s))  # a non-uniform parameter step
        t = spinal.estimate_tangents(f(u))
        e = ft(u)
        errs.append(max(np.linalg.norm(t[0] - e[0]), np.linalg.norm(t[-1] - e[-1])))
        # the bound never acts here: the default equals the unbounded rule
        t4 = spinal.estimate_tangents(f(u), method="five_point")
        assert np.array_equal(t, t4)
    orders = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert orders.min() >= 3.8, (errs, orders)


def _coarse_curves(count, n, seed):
    """Smooth random space curves sampled coarsely (like 20-point streamlines)."""
    rng = np.random.default_rng(seed)
    u = np.linspace(0, 1, 400)[:, None]
    out = []
    for _ in range(count):
        c = u * rng.normal(size=3) * rng.uniform(0.5, 3)
        for j in range(1, 6):
            c = c + rng.normal(size=3) * np.sin(j * np.pi * u + rng.uniform(0, 2 * np.pi)) / j
        out.append(c[np.sort(rng.choice(400, n, replace=False))])
    return np.array(out)


def test_end_tangents_within_half_the_turn_of_the_last_two_chords_and_45_degrees():
    pts = _coarse_curves(3000, 20, 1)
    flat = pts.reshape(-1, 3)
    lengths = [20] * len(pts)
    t = spinal.estimate_tangents(flat, lengths=lengths).reshape(pts.shape)
    lean, turn = _end_lean_and_turn(pts, t)
    cone = _cone(turn)
    assert np.all(lean <= cone + 1e-12), np.max(lean - cone)
    coarse = turn >= np.radians(20)
    assert coarse.sum() > 1000 and np.all(lean[coarse] <= turn[coarse] / 2 + 1e-12)
    # the unbounded one-sided quartic overshoots on many of these ends
    t4 = spinal.estimate_tangents(flat, lengths=lengths, method="five_point").reshape(pts.shape)
    lean4, _ = _end_lean_and_turn(pts, t4)
    assert np.mean(lean4 > turn + 1e-12) > 0.05
    assert np.sum((lean4 > np.pi / 4 + 1e-9) & (turn > np.pi / 4)) > 10  # the cap acts too
    # where the bound acts next to a turn under 30°, the end tangent is on the cone, in the
    # plane of the chord and the unbounded tangent (turned towards the chord); from 60° on,
    # a corner, it is the end chord
    acted = (lean4 > cone + 1e-9) & (turn < np.pi / 6)
    assert acted.sum() > 20
    assert np.allclose(lean[acted], cone[acted], atol=1e-12)
    assert np.all(lean[turn >= np.pi / 3] < 1e-7) and (turn >= np.pi / 3).sum() > 100
    # interior tangents are those of "five_point"
    assert np.array_equal(t[:, 1:-1], t4[:, 1:-1])
    # the frames and the sweeps use the default: their t column is this estimate, on every
    # curve (also those that turn by more than 60° between chords)
    ch = np.diff(pts, axis=1)
    assert (_angle(ch[:, 1:], ch[:, :-1]).max(axis=1) > np.pi / 3).sum() > 300
    F = spinal.frames(flat, lengths=lengths)
    np.testing.assert_allclose(F[:, :, 2], t.reshape(-1, 3), atol=1e-15)


def test_end_tangents_of_the_fornix_streamlines():
    dipy_data = pytest.importorskip("dipy.data")
    streamline = pytest.importorskip("dipy.tracking.streamline")
    io = pytest.importorskip("dipy.io.streamline")
    try:
        fname = dipy_data.get_fnames(name="fornix")
        lines = io.load_tractogram(fname, "same", bbox_valid_check=False).streamlines
    except (OSError, ValueError) as exc:  # no data available offline
        pytest.skip(f"fornix streamlines not available: {exc}")
    pts = np.array(streamline.set_number_of_points(list(lines), 20), dtype=np.float64)
    t = spinal.estimate_tangents(pts.reshape(-1, 3), lengths=[20] * len(pts)).reshape(pts.shape)
    lean, turn = _end_lean_and_turn(pts, t)
    assert np.all(lean <= _cone(turn) + 1e-12)


def test_ends_of_drifting_random_walks_lean_at_most_half_their_last_turn():
    """Coarse random walks with drift (12 points): the one-sided quartic leans ends up to 144°
    from their end chord; the default keeps every end within half the turn of its last two
    chords where that turn is 20° or more, and within 45°."""
    rng = np.random.default_rng(7)
    pts = np.array([np.cumsum(rng.normal(size=(12, 3)) + [1.5, 0, 0], 0) for _ in range(200)])
    flat, lengths = pts.reshape(-1, 3), [12] * len(pts)
    t = spinal.estimate_tangents(flat, lengths=lengths).reshape(pts.shape)
    lean, turn = _end_lean_and_turn(pts, t)
    t4 = spinal.estimate_tangents(flat, lengths=lengths, method="five_point").reshape(pts.shape)
    lean4, _ = _end_lean_and_turn(pts, t4)
    assert np.sum(lean4 > np.pi / 4) > 20  # the unbounded rule leans far
    assert np.all(lean <= np.pi / 4 + 1e-12)
    coarse = turn >= np.radians(20)
    assert coarse.sum() > 200
    assert np.all(lean[coarse] <= turn[coarse] / 2 + 1e-12), np.max(lean[coarse] - turn[coarse] / 2)
    assert np.all(lean <= turn + 1e-12)


def test_circle_rule_and_short_curves_keep_the_bound():
    pts = _coarse_curves(200, 6, 2)
    for method in ("circle", "five_point_bounded"):
        t = spinal.estimate_tangents(pts.reshape(-1, 3), lengths=[6] * len(pts), method=method)
        lean, turn = _end_lean_and_turn(pts, t.reshape(pts.shape))
        assert np.all(lean <= turn + 1e-12), method


def test_bundle_tangents_equal_the_tangents_of_each_curve():
    rng = np.random.default_rng(3)
    lengths = [2, 3, 4, 5, 9, 30]
    curves = [np.cumsum(rng.normal(size=(m, 3)), axis=0) for m in lengths]
    flat = np.concatenate(curves)
    for method in ("five_point_bounded", "five_point", "five_point_uniform", "circle"):
        t = spinal.estimate_tangents(flat, lengths=lengths, method=method)
        ref = np.concatenate([spinal.estimate_tangents(c, method=method) for c in curves])
        np.testing.assert_array_equal(t, ref)
    offsets = np.r_[0, np.cumsum(lengths)]
    np.testing.assert_array_equal(
        spinal.estimate_tangents(flat, offsets=offsets), spinal.estimate_tangents(flat, lengths=lengths)
    )
    # closed loops in a bundle (each may repeat its first point)
    u = np.linspace(0, 2 * np.pi, 13)[:-1]
    loop = np.c_[np.cos(u), np.sin(u), 0.1 * np.sin(2 * u)]
    both = np.r_[loop, loop[:1], 2 * loop]
    t = spinal.estimate_tangents(both, lengths=[13, 12], closed=True)
    np.testing.assert_array_equal(t[:13], spinal.estimate_tangents(np.r_[loop, loop[:1]], closed=True))
    np.testing.assert_array_equal(t[13:], spinal.estimate_tangents(2 * loop, closed=True))


def test_bundle_errors_name_the_curve_and_the_argument():
    pts = np.r_[np.eye(3), [[0, 0, 0], [1, 0, 0], [np.nan, 0, 0], [2, 0, 0]]].astype(float)
    with pytest.raises(ValueError, match=r"points: curve 1 \(rows 3 to 6\).*row 2"):
        spinal.estimate_tangents(pts, lengths=[3, 4])
    with pytest.raises(ValueError, match=r"points: curve 1 \(rows 3 to 5\): an open curve "
                                         r"needs at least 2 distinct points, got 1"):
        spinal.estimate_tangents(np.r_[np.eye(3), np.zeros((3, 3))], lengths=[3, 3])
    with pytest.raises(ValueError, match="lengths"):
        spinal.estimate_tangents(pts, lengths=[3, 3])
    with pytest.raises(TypeError, match="lengths, offsets"):
        spinal.estimate_tangents(pts, lengths=[3, 4], offsets=[0, 3, 7])
    with pytest.raises(ValueError, match="method"):
        spinal.estimate_tangents(pts, method="bounded")
