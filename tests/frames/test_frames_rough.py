"""Frames and estimated tangents on the polylines users have: jagged random walks, hairpins,
exact reversals. Every estimated tangent runs forwards along both chords at its sample (the
chord guard of :func:`spinal.estimate_tangents`), so every such curve gets frames."""

import numpy as np
import pytest

import spinal

RULES = ("five_point_bounded", "five_point", "five_point_uniform", "circle")


def _walks(count, seed, lo=3, hi=61):
    """Gaussian random walks of lo…hi−1 points (turns of every size)."""
    rng = np.random.default_rng(seed)
    return [np.cumsum(rng.normal(size=(rng.integers(lo, hi), 3)), axis=0) for _ in range(count)]


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


@pytest.mark.parametrize("rule", RULES)
def test_estimated_tangents_run_along_every_chord_of_random_walks(rule):
    walks = _walks(400, 1)
    t_all = spinal.estimate_tangents(walks, method=rule)
    start = 0
    for x in walks:
        n = len(x)
        t = t_all[start:start + n]
        start += n
        c = _unit(np.diff(x, axis=0))
        # every segment runs along the tangents at its ends (the unbounded rules' ends aside)
        ends = rule in ("five_point", "five_point_uniform") and n >= 5
        seg = (c * (t[:-1] + t[1:])).sum(axis=1)[1:-1 if ends else None]
        assert (seg > 1e-6).all(), (rule, n, seg.min())
        # interior tangents: a margin of at least half the bisector's against both chords
        p, q, ti = c[:-1], c[1:], t[1:-1]
        half = 0.5 * np.linalg.norm(p + q, axis=1)  # cos(φ/2)
        margin = np.minimum((ti * p).sum(1), (ti * q).sum(1))
        assert (margin >= 0.5 * half - 1e-12).all(), (rule, n)
    assert start == len(t_all)


def test_chord_guard_acts_only_where_the_estimate_is_far_from_a_chord():
    # on walks it acts often; on a smooth curve sampled a few times per turn never, so the
    # tangents there are the rule's own (exact on a circle whatever the sampling)
    for n in (6, 9, 40):
        u = 2 * np.pi * np.arange(n) / n
        circle = np.c_[np.cos(u), np.sin(u), np.zeros(n)]
        for rule in RULES:
            t = spinal.estimate_tangents(circle, closed=True, method=rule)
            np.testing.assert_allclose(t, np.c_[-np.sin(u), np.cos(u), np.zeros(n)],
                                       atol=1e-14)
    walks = _walks(400, 2, 10, 11)
    t = spinal.estimate_tangents(walks, method="five_point").reshape(400, 10, 3)
    x = np.array(walks)
    c = _unit(np.diff(x, axis=1))
    # where the five-point estimate stays within 60° of both chords it is unchanged: the
    # interior five-point quartic of uneven chords, computed here independently
    checked = 0
    for k in range(400):
        h = np.linalg.norm(np.diff(x[k], axis=0), axis=1)
        s = np.r_[0, np.cumsum(h)]
        for i in range(2, 8):
            w = _lagrange_derivative_weights(s[i - 2:i + 3] - s[i])
            v = w @ x[k, i - 2:i + 3]
            v /= np.linalg.norm(v)
            near = (min(v @ c[k, i - 1], v @ c[k, i]) >= 0.5 + 1e-9
                    and c[k, i - 1] @ c[k, i] >= np.cos(np.pi / 6) + 1e-9)  # under 30°
            circ = _circle_tangent(x[k, i - 1], x[k, i], x[k, i + 1])
            if near and v @ circ >= 0.5 + 1e-9:
                np.testing.assert_allclose(t[k, i], v, atol=1e-12)
                checked += 1
    assert checked > 50


def _lagrange_derivative_weights(s):
    """Weights of the derivative at 0 of the polynomial through the nodes ``s``."""
    m = len(s)
    V = np.vander(s, m, increasing=True).T  # rows: powers
    rhs = np.zeros(m)
    rhs[1] = 1.0
    return np.linalg.solve(V, rhs)


def _circle_tangent(a, b, c):
    p, q = b - a, c - b
    w = (q @ q) * p + (p @ p) * q
    return w / np.linalg.norm(w)


def test_frames_of_random_walks_are_rotations_along_the_estimated_tangents():
    walks = _walks(300, 3)
    F = spinal.frames(walks)
    assert F.shape == (sum(len(w) for w in walks), 3, 3)
    np.testing.assert_allclose(F.transpose(0, 2, 1) @ F, np.broadcast_to(np.eye(3), F.shape),
                               atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(F), 1, atol=1e-12)
    np.testing.assert_array_equal(F[:, :, 2], spinal.estimate_tangents(walks))
    # each curve of the bundle alone: the same frames, bit for bit (one long walk takes the
    # fused path of a single curve, the bundle the general one)
    long = np.cumsum(np.random.default_rng(4).normal(size=(5000, 3)), axis=0)
    for x in walks[:20] + [long]:
        np.testing.assert_array_equal(spinal.frames(x), spinal.frames([x])[: len(x)])
    for method in ("rotation", "projection"):
        G = spinal.frames(walks[:50], method=method)
        np.testing.assert_allclose(G[:, :, 2], F[: len(G), :, 2], atol=0)


def test_hairpins_and_exact_reversals_are_framed():
    for turn in (90, 170, 179, 179.999):
        a = np.radians(turn)
        d = np.array([np.cos(a), np.sin(a), 0])  # the outgoing chords, turned by `turn`
        x = np.array([[-2, 0, 0], [-1, 0, 0], [0, 0, 0], d, 2 * d])
        F = spinal.frames(x)
        np.testing.assert_allclose(np.linalg.det(F), 1, atol=1e-12)
        # a corner: the apex tangent is the chords' bisector
        bisector = (np.array([1, 0, 0]) + d) / np.linalg.norm([1, 0, 0] + d)
        np.testing.assert_allclose(F[2, :, 2], bisector, atol=1e-9)
    # out and straight back: the apex tangent is normal to the chord
    x = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [1, 0, 0], [0, 0, 0]])
    F = spinal.frames(x)
    assert F[2, 0, 2] == 0 and abs(np.linalg.norm(F[2, :, 2]) - 1) < 1e-15


def test_tangents_given_against_a_chord_are_still_refused():
    x = _walks(1, 5, 12, 13)[0]
    t = spinal.estimate_tangents(x)
    t[6:8] *= -1
    with pytest.raises(ValueError, match=r"points: the segment from row [567] to row [678] runs "
                                         r"against its tangents"):
        spinal.frames(x, t)
    # and out and back twice in a row leaves a segment with no forward tangent
    with pytest.raises(ValueError, match="points: the segment from row 1 to row 2"):
        spinal.frames(np.array([[0.0, 0, 0], [1, 0, 0], [0, 0, 0], [1, 0, 0]]))


def test_repeats_merge_with_guides_previous_and_constraints():
    """Steered frames merge repeated samples too: a per-row guide and previous are cut alike,
    a constraint on a repeat applies to the row it repeats, and errors name rows as given."""
    x = _walks(1, 9, 14, 15)[0]
    dup = np.insert(x, 5, x[4], axis=0)  # row 5 repeats row 4
    rows = np.r_[np.arange(5), 4, np.arange(5, len(x))]
    g = np.tile([0.0, 0, 1], (len(x), 1)) + 0.1 * np.cos(np.arange(len(x)))[:, None]
    np.testing.assert_array_equal(spinal.frames(dup, guide=g[rows]),
                                  spinal.frames(x, guide=g)[rows])
    prev = spinal.frames(x)
    np.testing.assert_array_equal(spinal.frames(dup, previous=prev[rows], previous_twist=True),
                                  spinal.frames(x, previous=prev, previous_twist=True)[rows])
    v = np.cross(spinal.frames(x)[9, :, 2], [0.3, 0.2, 1.0])
    np.testing.assert_array_equal(spinal.frames(dup, constraints={5: v, 10: v}),
                                  spinal.frames(x, constraints={4: v, 9: v})[rows])
    with pytest.raises(ValueError, match="constraints: two constraints of curve 0 fall on one "
                                         "sample"):
        spinal.frames(dup, constraints={4: v, 5: v})
    # a given tangent against its chord after the repeat: the row as given
    t = spinal.estimate_tangents(dup)
    t[11:13] *= -1
    with pytest.raises(ValueError, match=r"points: the segment from row 1[012] to row 1[123] "):
        spinal.frames(dup, t)
    # the sweep names the radius' row as given
    r = np.full(len(dup), 0.1)
    r[11] = -1
    with pytest.raises(ValueError, match=r"radius: must be positive and finite, got -1(\.0)? at "
                                         r"row 11"):
        spinal.tube(dup, r)
    # frames in time, one turn per step: repeats merged step by step
    P = np.stack([dup, dup + 0.01])
    np.testing.assert_allclose(spinal.frames_in_time(P, previous_twist=False),
                               spinal.frames_in_time(np.stack([x, x + 0.01]),
                                                     previous_twist=False)[:, rows], atol=1e-12)


def test_invalid_curves_are_skipped_by_frames_and_tangents_on_request():
    """on_invalid='skip': curves with a NaN or too few distinct points are left out with a
    SkippedCurvesWarning naming them; their rows are NaN and the other curves get the frames
    (tangents) of the call without them, per-row and per-curve arguments cut alike."""
    rng = np.random.default_rng(8)
    good = [np.cumsum(rng.normal(size=(n, 3)), axis=0) for n in (5, 9, 6)]
    nan = good[1].copy()
    nan[4] = np.nan
    curves = [good[0], nan, good[2], np.ones((3, 3))]
    rows = np.r_[0, np.cumsum([len(c) for c in curves])]
    with pytest.raises(ValueError, match="curve 1"):
        spinal.frames(curves)
    kept = [good[0], good[2]]
    for call, ref, kw in (
        (spinal.frames, spinal.frames(kept, guide=np.tile([0, 0, 1.0], (11, 1))),
         {"guide": np.tile([0, 0, 1.0], (sum(len(c) for c in curves), 1))}),
        (spinal.estimate_tangents, spinal.estimate_tangents(kept), {}),
    ):
        with pytest.warns(spinal.SkippedCurvesWarning, match="with NaN or inf: 1; with fewer "
                          "than 2 distinct points: 3") as rec:
            out = call(curves, on_invalid="skip", **kw)
        np.testing.assert_array_equal(rec[0].message.curves, [1, 3])
        np.testing.assert_array_equal(out[rows[0]:rows[1]], ref[:5])
        np.testing.assert_array_equal(out[rows[2]:rows[3]], ref[5:])
        assert np.isnan(out[rows[1]:rows[2]]).all() and np.isnan(out[rows[3]:]).all()
    assert not np.isnan(nan[:4]).any()  # the input is not modified
    with pytest.raises(TypeError, match="on_invalid: 'skip' does not take constraints"):
        spinal.frames(curves, on_invalid="skip", constraints=[(0, [1.0, 0, 0])])
