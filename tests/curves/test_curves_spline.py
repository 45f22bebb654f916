"""spinal.curves.Spline: each kind against scipy.interpolate or a closed form, continuity,
arc length against scipy.integrate.quad, use with frames/tube, and the argument errors."""

import math
import pickle
import time
from itertools import pairwise

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.interpolate import BSpline, CubicHermiteSpline, CubicSpline

import spinal
from spinal.curves import Spline

KINDS = ["catmull_rom", "natural_cubic", "bspline"]
CASES = [(k, c) for k in KINDS for c in (False, True)]


def _ids(case):
    return f"{case[0]}-{'closed' if case[1] else 'open'}"


def random_points(n, seed):
    return np.random.default_rng(seed).normal(size=(n, 3))


def chord_knots(p, closed):
    """The chord-length knots (closed: round the loop) and the points with the first
    appended when closed."""
    q = np.vstack([p, p[:1]]) if closed else p
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(q, axis=0), axis=1))]), q


def assert_rel(a, b, tol=1e-12):
    assert np.abs(a - b).max() <= tol * np.abs(b).max(), np.abs(a - b).max()


def derivatives(s, u):
    return [s.point(u), s.d1(u), s.d2(u), s.d3(u)]


def sample_inside(s, n=601):
    """Parameters over the domain, the end left out (a closed spline wraps it to the start,
    where the third derivative jumps)."""
    return np.linspace(*s.domain, n)[:-1]


# ------------------------------------------------------------------------ each kind


@pytest.mark.parametrize("closed", [False, True], ids=["open", "closed"])
def test_natural_cubic_equals_scipy_cubic_spline(closed):
    p = random_points(11, 0)
    s = Spline(p, "natural_cubic", closed=closed)
    t, q = chord_knots(p, closed)
    ref = CubicSpline(t, q, bc_type="periodic" if closed else "natural")
    np.testing.assert_array_equal(s.knots, t)
    assert s.domain == (0.0, t[-1])
    u = np.linspace(0, t[-1], 997)
    for k, got in enumerate(derivatives(s, u)):
        assert_rel(got, ref(u, k))


def _parabola_slopes(t, q, closed):
    """Slopes at the knots from numpy's least-squares fit of a parabola (exact: 3 points)
    through each point and its neighbours; open ends: the parabola through the end three."""
    n = len(t) - 1 if closed else len(t)
    m = np.empty((n, 3))
    for i in range(n):
        if closed:
            L = t[-1]
            tt = np.array([t[n - 1] - L if i == 0 else t[i - 1], t[i], t[i + 1]])
            pp = q[[(i - 1) % n, i, (i + 1) % n]]
        else:
            j = min(max(i - 1, 0), n - 3)
            tt, pp = t[j:j + 3], q[j:j + 3]
        for x in range(3):
            c = np.polyfit(tt - t[i], pp[:, x], 2)
            m[i, x] = c[1]  # the derivative at t_i of c0 (t − t_i)² + c1 (t − t_i) + c2
    return np.vstack([m, m[:1]]) if closed else m


@pytest.mark.parametrize("closed", [False, True], ids=["open", "closed"])
def test_catmull_rom_equals_scipy_hermite_spline_with_parabola_slopes(closed):
    p = random_points(10, 1)
    s = Spline(p, "catmull_rom", closed=closed)
    t, q = chord_knots(p, closed)
    ref = CubicHermiteSpline(t, q, _parabola_slopes(t, q, closed))
    u = sample_inside(s)
    for k, got in enumerate(derivatives(s, u)):
        assert_rel(got, ref(u, k))


@pytest.mark.parametrize("closed", [False, True], ids=["open", "closed"])
def test_fewest_points_equal_scipy(closed):
    """The smallest systems: 3 points (natural open: one unknown; periodic: the smallest
    cyclic system), and the B-spline's 4 (open) or 3 (closed) control points."""
    p = random_points(3, 22)
    s = Spline(p, "natural_cubic", closed=closed)
    t, q = chord_knots(p, closed)
    ref = CubicSpline(t, q, bc_type="periodic" if closed else "natural")
    u = sample_inside(s, 101)
    for k, got in enumerate(derivatives(s, u)):
        assert_rel(got, ref(u, k))
    p = random_points(3 if closed else 4, 23)
    s = Spline(p, "bspline", closed=closed)
    knots = np.arange(-3.0, 7) if closed else np.r_[0, 0, 0, 0, 1, 1, 1, 1.0]
    ref = BSpline(knots, np.vstack([p[-1:], p, p[:2]]) if closed else p, 3)
    u = sample_inside(s, 101)
    for k, got in enumerate(derivatives(s, u)):
        assert_rel(got, ref(u, k))


def test_catmull_rom_is_the_barry_goldman_pyramid():
    """Barry & Goldman (1988): linear interpolation of points → of the lines → of the
    parabolas, on the chordal knots; on the pieces with two neighbours each side."""
    p = random_points(8, 2)
    s = Spline(p, "catmull_rom")
    t = s.knots

    def lerp(a, b, ta, tb, u):
        w = ((u - ta) / (tb - ta))[:, None]
        return (1 - w) * a + w * b

    for i in range(1, len(p) - 2):
        u = np.linspace(t[i], t[i + 1], 21)
        t0, t1, t2, t3 = t[i - 1:i + 3]
        p0, p1, p2, p3 = p[i - 1:i + 3]
        l01, l12, l23 = lerp(p0, p1, t0, t1, u), lerp(p1, p2, t1, t2, u), lerp(p2, p3, t2, t3, u)
        l012, l123 = lerp(l01, l12, t0, t2, u), lerp(l12, l23, t1, t3, u)
        np.testing.assert_allclose(s.point(u), lerp(l012, l123, t1, t2, u), atol=1e-13)


def test_catmull_rom_on_equal_chords_is_the_classic_catmull_rom_spline():
    """A regular polygon has equal chords h: then m_i = (p_{i+1} − p_{i−1})/(2h)
    (Catmull & Rom 1974 on a uniform parameter, scaled by 1/h)."""
    a = np.linspace(0, 2 * np.pi, 7, endpoint=False)
    p = np.column_stack([np.cos(a), np.sin(a), np.zeros(7)])
    s = Spline(p, "catmull_rom", closed=True)
    h = np.linalg.norm(p[1] - p[0])
    m = (np.roll(p, -1, axis=0) - np.roll(p, 1, axis=0)) / (2 * h)
    np.testing.assert_allclose(s.d1(s.knots[:-1]), m, atol=1e-14)


def test_catmull_rom_through_unequally_spaced_collinear_points_is_the_line_at_unit_speed():
    d = np.array([1.0, 2.0, -0.5]) / np.linalg.norm([1.0, 2.0, -0.5])
    t = np.array([0.0, 0.1, 1.7, 1.9, 4.0, 4.05])
    p = np.array([0.3, -1.0, 2.0]) + t[:, None] * d
    s = Spline(p, "catmull_rom")
    np.testing.assert_allclose(s.knots, t, atol=1e-14)
    u = np.linspace(0, t[-1], 301)
    np.testing.assert_allclose(s.point(u), p[0] + u[:, None] * d, atol=1e-13)
    np.testing.assert_allclose(s.d1(u), np.broadcast_to(d, (301, 3)), atol=1e-13)
    np.testing.assert_allclose(s.d2(u), 0, atol=1e-12)


@pytest.mark.parametrize("closed", [False, True], ids=["open", "closed"])
def test_clamped_and_periodic_bspline_equal_scipy_bspline(closed):
    p = random_points(9, 3)
    n = len(p)
    s = Spline(p, "bspline", closed=closed)
    if closed:  # the control polygon wrapped: p_{n−1}, p_0 … p_{n−1}, p_0, p_1
        ref = BSpline(np.arange(-3.0, n + 4), np.vstack([p[-1:], p, p[:2]]), 3)
        assert s.domain == (0.0, n)
    else:
        knots = np.r_[0, 0, 0, np.arange(n - 2.0), n - 3, n - 3, n - 3]
        ref = BSpline(knots, p, 3)
        assert s.domain == (0.0, n - 3)
    u = sample_inside(s)
    for k, got in enumerate(derivatives(s, u)):
        assert_rel(got, ref(u, k))


def test_clamped_bspline_interpolates_the_end_points_along_the_end_legs():
    p = random_points(7, 4)
    s = Spline(p, "bspline")
    np.testing.assert_allclose(s.point([0.0, 4.0]), p[[0, -1]], atol=1e-14)
    np.testing.assert_allclose(s.d1([0.0, 4.0]), 3 * (p[[1, -1]] - p[[0, -2]]), atol=1e-13)


def test_periodic_bspline_passes_through_the_weighted_means_at_integers():
    p = random_points(6, 5)
    s = Spline(p, "bspline", closed=True)
    want = (np.roll(p, 1, axis=0) + 4 * p + np.roll(p, -1, axis=0)) / 6
    np.testing.assert_allclose(s.point(np.arange(6.0)), want, atol=1e-14)


def test_four_control_points_clamped_bspline_is_the_bezier_curve():
    from spinal.curves import Bezier

    p = random_points(4, 6)
    u = np.linspace(0, 1, 50)
    b = Bezier(p)
    for got, want in zip(derivatives(Spline(p, "bspline"), u), derivatives(b, u)):
        np.testing.assert_allclose(got, want, atol=1e-12)


@pytest.mark.parametrize("kind", ["catmull_rom", "natural_cubic"])
def test_two_points_give_the_straight_chord(kind):
    p = np.array([[1.0, 2.0, 3.0], [4.0, 6.0, 3.0]])
    s = Spline(p, kind)
    assert s.domain == (0.0, 5.0)
    u = np.linspace(0, 5, 11)
    np.testing.assert_allclose(s.point(u), p[0] + u[:, None] * [0.6, 0.8, 0.0], atol=1e-14)


# ---------------------------------------------------------------------- continuity


def _jumps(s, k):
    """The largest jump of the k-th derivative across the interior knots (closed: and the
    seam), relative to its size. Each side's limit at a knot is the Taylor expansion of
    that side's cubic from 1e-6 (relative) away, exact for cubics up to rounding."""
    lo, hi = s.domain
    eps = 1e-6 * (hi - lo)
    knots = s.knots[1:] if s.closed else s.knots[1:-1]
    f = [s.point, s.d1, s.d2, s.d3]

    def limit(u, e):  # Σ_j x^(k+j)(u − e) e^j / j!
        return sum(f[k + j](u - e) * e**j / math.factorial(j) for j in range(4 - k))

    right_of = np.where(knots == hi, lo, knots) if s.closed else knots
    left, right = limit(knots, eps), limit(right_of, -eps)
    return np.abs(left - right).max() / np.abs(f[k](s.knots[:-1])).max()


@pytest.mark.parametrize("case", CASES, ids=_ids)
def test_smoothness_at_the_knots(case):
    """Catmull–Rom is C¹ (its x″ jumps), the natural and B-splines C² (x‴ jumps); closed
    splines across the seam too."""
    kind, closed = case
    s = Spline(random_points(9, 7), kind, closed=closed)
    smooth = 1 if kind == "catmull_rom" else 2
    for k in range(smooth + 1):
        assert _jumps(s, k) < 1e-10, k
    assert _jumps(s, smooth + 1) > 1e-3


def test_natural_ends_have_zero_second_derivative():
    s = Spline(random_points(8, 8), "natural_cubic")
    np.testing.assert_allclose(s.d2(list(s.domain)), 0, atol=1e-12)


@pytest.mark.parametrize("case", CASES, ids=_ids)
def test_derivatives_match_finite_differences(case):
    s = Spline(random_points(8, 9), *case)
    lo, hi = s.domain
    u = np.linspace(lo, hi, 17)[1:-1] + 0.013 * (hi - lo)  # away from the knots
    h = 1e-4 * (hi - lo)
    for f, g in [(s.point, s.d1), (s.d1, s.d2), (s.d2, s.d3)]:
        fd = (-f(u + 2 * h) + 8 * f(u + h) - 8 * f(u - h) + f(u - 2 * h)) / (12 * h)
        assert np.abs(fd - g(u)).max() < 1e-8 * (np.abs(g(u)).max() + 1)


@pytest.mark.parametrize("kind", KINDS)
def test_closed_splines_wrap_u_periodically(kind):
    s = Spline(random_points(7, 10), kind, closed=True)
    L = s.domain[1]
    u = np.linspace(0, L, 23)
    for f in (s.point, s.d1, s.d2):
        np.testing.assert_allclose(f(u + 3 * L), f(u), atol=1e-11)
        np.testing.assert_allclose(f(u - L), f(u), atol=1e-11)
    np.testing.assert_array_equal(s.point([L]), s.point([0.0]))


def test_open_spline_refuses_u_outside_its_domain():
    s = Spline(random_points(5, 11), "natural_cubic")
    hi = s.domain[1]
    s.point([0.0, hi, hi * (1 + 1e-13), -1e-13 * hi])  # within the rounding slack
    with pytest.raises(ValueError, match=r"^u: .* is outside the domain"):
        s.point([0.5, hi * (1 + 1e-9)])
    with pytest.raises(ValueError, match=r"^u: -0\.1 is outside the domain"):
        s.d1(-0.1)


# ----------------------------------------------------------------------- arc length


def circle_points(n, closed):
    a = np.linspace(0, 2 * np.pi, n, endpoint=not closed)
    return np.column_stack([np.cos(a), np.sin(a), np.zeros(n)])


@pytest.mark.parametrize("closed", [False, True], ids=["open", "closed"])
def test_natural_spline_through_points_of_the_unit_circle_has_length_2pi(closed):
    s = Spline(circle_points(400, closed), "natural_cubic", closed=closed)
    # interpolation error O(h⁴) in the periodic case, O(h²) near the natural ends
    assert abs(s.length - 2 * np.pi) < (1e-9 if closed else 1e-6)


def _quad_lengths(s, u):
    def speed(x):
        return float(s.speed([x])[0])

    # splitting at the knots keeps quad on smooth integrands
    out = []
    for a, b in pairwise(u):
        cuts = [a, *s.knots[(s.knots > a) & (s.knots < b)], b]
        out.append(sum(quad(speed, x, y, epsabs=0, epsrel=1e-13)[0]
                       for x, y in pairwise(cuts)))
    return np.array(out)


@pytest.mark.parametrize("case", CASES, ids=_ids)
def test_arc_length_parameters_are_equally_spaced_by_scipy_quad(case):
    kind, closed = case
    s = Spline(random_points(7, 12), kind, closed=closed)
    n = 40
    u = s.arc_length_parameters(n)
    assert u.shape == (n,) and np.all(np.diff(u) > 0)
    assert u[0] == s.domain[0] and (closed or u[-1] == s.domain[1])
    ends = np.append(u, s.domain[1]) if closed else u
    steps = _quad_lengths(s, ends)
    assert abs(steps.sum() - s.length) < 1e-12 * s.length
    np.testing.assert_allclose(steps, s.length / (n if closed else n - 1), rtol=1e-11)


def test_arc_length_through_a_bspline_cusp():
    """Three equal control points make a corner where |x′| = 0 (the speed's zero at a knot)."""
    p = [[0, 0, 0], [1, 0, 0], [1, 0, 0], [1, 0, 0], [1, 1, 0], [2, 1, 0.5]]
    s = Spline(p, "bspline")
    assert np.linalg.norm(s.d1([1.0])) < 1e-14
    u = s.arc_length_parameters(15)
    steps = _quad_lengths(s, u)
    np.testing.assert_allclose(steps, s.length / 14, rtol=1e-10)


def test_samples_of_a_straight_spline_are_evenly_spaced_on_the_line():
    p = np.array([[0.0, 0, 0], [0.5, 0, 0], [3, 0, 0], [3.2, 0, 0]])
    s = Spline(p, "natural_cubic")
    assert abs(s.length - 3.2) < 1e-14
    x = s.sample_arc_length(9)
    np.testing.assert_allclose(x[:, 0], np.linspace(0, 3.2, 9), atol=1e-13)


def test_sample_arc_length_of_a_closed_spline_does_not_repeat_the_first_point():
    s = Spline(circle_points(50, True), "catmull_rom", closed=True)
    x = s.sample_arc_length(30)
    assert x.shape == (30, 3)
    np.testing.assert_allclose(x[0], [1, 0, 0], atol=1e-15)
    gaps = np.linalg.norm(np.diff(np.vstack([x, x[:1]]), axis=0), axis=1)
    np.testing.assert_allclose(gaps, gaps.mean(), rtol=1e-4)  # chords of equal arcs
    np.testing.assert_allclose(x, s.point(s.arc_length_parameters(30)))


# ------------------------------------------------------------- with frames and tubes


@pytest.mark.parametrize("kind", KINDS)
def test_frames_of_a_spline_are_rotations_along_its_tangent(kind):
    s = Spline(random_points(8, 13), kind)
    u = s.arc_length_parameters(200)
    F = spinal.frames(s, u=u)
    assert F.shape == (200, 3, 3)
    assert np.abs(np.einsum("nji,njk->nik", F, F) - np.eye(3)).max() < 1e-12
    np.testing.assert_allclose(np.linalg.det(F), 1, atol=1e-12)
    np.testing.assert_allclose(F[:, :, 2], s.tangent(u), atol=1e-12)


def test_frames_of_a_closed_spline_need_u_over_the_whole_period():
    s = Spline(random_points(6, 14), "natural_cubic", closed=True)
    u = np.append(s.arc_length_parameters(100), s.domain[1])
    F = spinal.frames(s, u=u, closed=True)
    np.testing.assert_allclose(F[-1], F[0], atol=1e-12)


@pytest.mark.parametrize("closed", [False, True], ids=["open", "closed"])
def test_tube_round_arc_length_samples_is_watertight(closed):
    p = 3 * random_points(8, 15)
    s = Spline(p, "catmull_rom", closed=closed)
    mesh = spinal.tube(s.sample_arc_length(200), 0.1, closed=closed)
    assert mesh.is_watertight


# -------------------------------------------------------------- arguments and errors


@pytest.mark.parametrize("points, kwargs, message", [
    (np.zeros((5, 2)), {}, r"^points: expected an array of shape \(n, 3\), got shape \(5, 2\)"),
    (np.zeros(3), {}, r"^points: expected an array of shape \(n, 3\)"),
    ([[0, 0, 0], [1, np.nan, 0], [2, 0, 0]], {}, "^points: non-finite value at row 1"),
    ([[0, 0, 0], [1, 0, np.inf], [2, 0, 0]], {"kind": "bspline"}, "^points: non-finite"),
    ([[0, 0, 0]], {}, "^points: kind='catmull_rom' needs at least 2 points, got 1"),
    ([[0, 0, 0], [1, 0, 0]], {"closed": True}, "^points: .* at least 3 points when closed"),
    (np.eye(3), {"kind": "bspline"}, "^points: kind='bspline' needs at least 4 points, got 3"),
    (np.eye(3)[:2], {"kind": "bspline", "closed": True}, "^points: .* at least 3 points when"),
    ([[0, 0, 0], [1, 0, 0], [1, 0, 0], [2, 0, 0]], {}, "^points: rows 1 and 2 coincide"),
    ([[0, 0, 0], [1, 0, 0], [1, 0, 0]], {"kind": "natural_cubic"},
     "^points: rows 1 and 2 coincide"),
    ([[0, 0, 0], [1, 0, 0], [0, 0, 0], [0, 0, 0]], {"closed": True},
     r"^points: rows 2 and 0 coincide \(the closing chord\)"),
])
def test_bad_points_are_refused_with_a_message_naming_them(points, kwargs, message):
    with pytest.raises(ValueError, match=message):
        Spline(points, **kwargs)


def test_bspline_accepts_repeated_control_points():
    Spline([[0, 0, 0], [1, 0, 0], [1, 0, 0], [2, 0, 0]], "bspline")


def test_bad_kind_and_closed_are_refused():
    with pytest.raises(ValueError, match="^kind: unknown value 'cubic'"):
        Spline(np.eye(3), "cubic")
    with pytest.raises(TypeError, match="^closed: expected True or False"):
        Spline(np.eye(3), closed=1)
    with pytest.raises(TypeError, match="^points: expected an array of real numbers"):
        Spline("abc")
    with pytest.raises(ValueError, match="^n: a sample count must be at least 2"):
        Spline(np.eye(3)).arc_length_parameters(1)


def test_closed_spline_drops_a_repeated_first_point():
    p = random_points(6, 16)
    for kind in KINDS:
        a = Spline(p, kind, closed=True)
        b = Spline(np.vstack([p, p[:1]]), kind, closed=True)
        assert b.points.shape == (6, 3) and b.domain == a.domain
        u = np.linspace(*a.domain, 50)
        np.testing.assert_array_equal(a.point(u), b.point(u))


@pytest.mark.parametrize("case", CASES, ids=_ids)
def test_inputs_are_never_modified(case):
    p = random_points(7, 17)
    keep = p.copy()
    p.setflags(write=False)
    s = Spline(p, *case)
    u = s.arc_length_parameters(20)
    u.setflags(write=False)
    uk = u.copy()
    derivatives(s, u)
    spinal.frames(s, u=np.append(u, s.domain[1]) if case[1] else u, closed=case[1])
    np.testing.assert_array_equal(p, keep)
    np.testing.assert_array_equal(u, uk)
    assert not s.points.flags.writeable and not s.knots.flags.writeable
    assert s.points is not p


def test_other_dtypes_and_lists_are_accepted():
    p = random_points(5, 18)
    u = np.linspace(0, 1, 7)
    want = Spline(p, "natural_cubic").point(u)
    np.testing.assert_array_equal(Spline(p.tolist(), "natural_cubic").point(u), want)
    p32 = p.astype(np.float32)
    np.testing.assert_array_equal(Spline(p32, "natural_cubic").point(u),
                                  Spline(p32.astype(np.float64), "natural_cubic").point(u))
    np.testing.assert_array_equal(Spline(np.asfortranarray(p), "natural_cubic").point(u), want)


def test_spline_pickles_and_shows_its_kind():
    s = Spline(random_points(5, 19), "bspline", closed=True)
    t = pickle.loads(pickle.dumps(s))
    u = np.linspace(0, 5, 11)
    np.testing.assert_array_equal(t.point(u), s.point(u))
    assert t.length == s.length
    assert repr(s) == "Spline(<5 points>, kind='bspline', closed=True)"
    assert type(s).__module__ == "spinal.curves"


def test_a_million_evaluations_take_well_under_a_second():
    """CPU time, not wall time: a loaded machine stretches the wall clock, not the work."""
    s = Spline(random_points(200, 20), "natural_cubic")
    u = np.random.default_rng(21).uniform(*s.domain, 1_000_000)
    best = np.inf
    for _ in range(3):
        t0 = time.process_time()
        x = s.point(u)
        best = min(best, time.process_time() - t0)
    assert x.shape == (1_000_000, 3)
    assert best < 0.5, best


def test_spline_lengths_at_extreme_scales_are_exact_or_refused_by_name():
    """A B-spline's length scales with its control points from 1e-170 to 1e170 (no
    overflow or underflow in the speed); an interpolating spline, whose pieces hold the
    chord lengths cubed, refuses chords outside 1e-100 … 1e100 by naming the points and is
    exact inside that range."""
    P = np.random.default_rng(11).normal(size=(8, 3))
    ref = Spline(P, "bspline").length
    for sc in (1e-170, 1e170):
        assert abs(Spline(P * sc, "bspline").length / (ref * sc) - 1) < 1e-12
    for kind in ("natural_cubic", "catmull_rom"):
        ref = Spline(P, kind).length
        for sc in (1e-90, 1e90):
            assert abs(Spline(P * sc, kind).length / (ref * sc) - 1) < 1e-12
        for sc in (1e-170, 1e170):
            with pytest.raises(ValueError, match="^points: chords from .* leave the range"):
                Spline(P * sc, kind)
