"""Steered frames: interior constraints with the two twist rules, guide vectors, coherence
over time (``spinal.frames(constraints=, twist_rule=, guide=, previous=)`` and
``spinal.frames_in_time``).

References are independent of the implementation: the twist of every interval in closed form
(arc length, or the turning of the tangent), a numerical minimisation (scipy) of the discrete
total (squared) angular speed, a guide that is an exact RMF turned by a known function, and
the change of a helix's frames while its pitch changes."""

import itertools

import numpy as np
import pytest
from scipy.optimize import minimize

import spinal


def helix(n=120, b=0.4, span=4 * np.pi, uneven=True):
    k = np.arange(n)
    u = span * (k + (0.3 * np.sin(1.7 * k) if uneven else 0.0)) / (n - 1)
    u = np.sort(u)
    return np.c_[np.cos(u), np.sin(u), b * u]


def wiggle(n=160):
    u = np.linspace(0, 3.0, n) + 0.004 * np.sin(np.arange(n) * 1.3)
    return np.c_[3 * np.cos(u), 2 * np.sin(u) + 0.3 * np.sin(4 * u), 0.4 * u + 0.5 * np.sin(3 * u)]


def signed(a, b, t):
    """Angle turning a into b about t (rows)."""
    return np.arctan2(np.einsum("ij,ij->i", np.cross(a, b), t), np.einsum("ij,ij->i", a, b))


def twist_of(F, F0):
    """The twist of frames F about t from the RMF F0, unwrapped along the rows."""
    return np.unwrap(signed(F0[:, :, 0], F[:, :, 0], F0[:, :, 2]))


def turned(F0, i, beta):
    r, s = F0[i, :, 0], F0[i, :, 1]
    return np.cos(beta) * r + np.sin(beta) * s


def wrap(a):
    w = np.mod(a, 2 * np.pi)
    return np.where(w > np.pi, w - 2 * np.pi, w)


def weights(F, x, rule):
    """Cumulative weights of the rule: chord length, or the turning of the tangent."""
    if rule == "arc_length":
        h = np.linalg.norm(np.diff(x, axis=0), axis=1)
    else:
        t = F[:, :, 2]
        h = np.arctan2(np.linalg.norm(np.cross(t[:-1], t[1:]), axis=1),
                       np.einsum("ij,ij->i", t[:-1], t[1:]))
    return np.r_[0.0, np.cumsum(h)]


@pytest.mark.parametrize("rule", ["arc_length", "min_angular_speed"])
@pytest.mark.parametrize("rows,betas,turns", [
    ((20, 85), (0.4, -2.0), 0),
    ((10, 50, 100), (1.0, -2.5, 2.9), 0),
    ((10, 50, 100), (1.0, -2.5, 2.9), 1),
    ((10, 50, 100), (1.0, -2.5, 2.9), [2, -1]),
])
def test_interior_constraints_on_a_helix_twist_per_interval_by_the_rule(rule, rows, betas, turns):
    x = helix()
    F0 = spinal.frames(x)
    cons = {k: turned(F0, k, b) for k, b in zip(rows, betas)}
    F = spinal.frames(x, constraints=cons, twist_rule=rule, turns=turns)
    for k, g in cons.items():
        assert np.abs(F[k, :, 0] - g).max() < 1e-12
    assert np.allclose(F[:, :, 2], F0[:, :, 2], atol=0, rtol=0) or \
        np.abs(F[:, :, 2] - F0[:, :, 2]).max() < 1e-15
    # the twist, exactly as the rule says
    alpha = signed(F0[:, :, 0], F[:, :, 0], F0[:, :, 2])
    w = weights(F0, x, rule)
    want = np.empty(len(x))
    ks = list(rows)
    tl = [turns] * (len(ks) - 1) if np.isscalar(turns) else list(turns)
    want[: ks[0] + 1] = betas[0]
    acc = betas[0]
    for j in range(len(ks) - 1):
        a, b = ks[j], ks[j + 1]
        total = wrap(betas[j + 1] - betas[j]) + 2 * np.pi * tl[j]
        want[a : b + 1] = acc + total * (w[a : b + 1] - w[a]) / (w[b] - w[a])
        acc += total
    want[ks[-1]:] = want[ks[-1]]
    assert np.abs(wrap(alpha - want)).max() < 1e-12
    assert np.abs(np.einsum("nij,nik->njk", F, F) - np.eye(3)).max() < 1e-12


def test_the_two_rules_differ_where_the_curvature_varies():
    x = wiggle()
    F0 = spinal.frames(x)
    cons = {5: turned(F0, 5, 0.0), 150: turned(F0, 150, 2.5)}
    a = twist_of(spinal.frames(x, constraints=cons), F0)
    b = twist_of(spinal.frames(x, constraints=cons, twist_rule="min_angular_speed"), F0)
    assert np.abs(a - b).max() > 0.05


def discrete_speed(dalpha, theta, h, squared):
    """The discrete total (squared) angular speed of twist increments over one interval."""
    if squared:
        return np.sum((theta**2 + dalpha**2) / h)
    return np.sum(np.sqrt(theta**2 + dalpha**2))


@pytest.mark.parametrize("rule,squared", [("min_angular_speed", False), ("arc_length", True)])
def test_each_rule_minimises_its_discrete_angular_speed(rule, squared):
    """scipy minimises the discrete ∫|ω| ds (min_angular_speed, Zheng eq. 7.5) or ∫|ω|² ds
    (arc_length, eq. 7.8) over the twist increments of each interval, the interval's total
    twist fixed; the library's increments agree to 1e-8."""
    x = wiggle()
    F0 = spinal.frames(x)
    ks = [5, 60, 150]
    cons = {k: turned(F0, k, b) for k, b in zip(ks, (0.3, 2.9, -1.2))}
    F = spinal.frames(x, constraints=cons, twist_rule=rule)
    alpha = twist_of(F, F0)
    t = F0[:, :, 2]
    theta = np.arctan2(np.linalg.norm(np.cross(t[:-1], t[1:]), axis=1),
                       np.einsum("ij,ij->i", t[:-1], t[1:]))
    h = np.linalg.norm(np.diff(x, axis=0), axis=1)
    for a, b in itertools.pairwise(ks):
        got = np.diff(alpha[a : b + 1])
        total = got.sum()
        th, hh = theta[a:b], h[a:b]

        def f(y, th=th, hh=hh, total=total):
            d = np.r_[y, total - y.sum()]
            return discrete_speed(d, th, hh, squared)

        def grad(y, th=th, hh=hh, total=total):
            d = np.r_[y, total - y.sum()]
            g = 2 * d / hh if squared else d / np.sqrt(th**2 + d**2)
            return g[:-1] - g[-1]

        y0 = np.full(b - a - 1, total / (b - a))
        res = minimize(f, y0, jac=grad, method="BFGS", options={"gtol": 1e-14, "maxiter": 10000})
        best = np.r_[res.x, total - res.x.sum()]
        assert np.abs(best - got).max() < 1e-8, (rule, np.abs(best - got).max())
        assert f(got[:-1]) <= res.fun + 1e-12


def test_end_and_closed_are_special_cases():
    x = helix(uneven=True)
    F0 = spinal.frames(x)
    v = np.array([0.3, -1.0, 0.5])
    for turns in (0, 2):
        want = spinal.frames(x, end=v, turns=turns)
        got = spinal.frames(x, constraints={0: F0[0, :, 0], -1: v}, turns=turns)
        assert np.abs(got - want).max() < 1e-12
        got = spinal.frames(x, end=v, turns=turns, constraints={})
        assert np.abs(got - want).max() < 1e-12
    u = np.linspace(0, 2 * np.pi, 150, endpoint=False)
    loop = np.c_[(2 + np.cos(3 * u)) * np.cos(2 * u), (2 + np.cos(3 * u)) * np.sin(2 * u),
                 np.sin(3 * u)]
    for turns in (0, -1):
        want = spinal.frames(loop, closed=True, turns=turns)
        got = spinal.frames(loop, closed=True, turns=turns, constraints={})
        assert np.abs(got - want).max() < 1e-12
        got = spinal.frames(loop, closed=True, turns=turns, constraints={0: want[0]})
        assert np.abs(got - want).max() < 1e-12


@pytest.mark.parametrize("rule", ["arc_length", "min_angular_speed"])
def test_closed_curve_constraints_run_round_the_seam(rule):
    u = np.linspace(0, 2 * np.pi, 200, endpoint=False)
    loop = np.c_[(2 + np.cos(3 * u)) * np.cos(2 * u), (2 + np.cos(3 * u)) * np.sin(2 * u),
                 np.sin(3 * u)]
    F0 = spinal.frames(loop, closed=True)
    ks = [30, 90, 170]
    cons = {k: turned(F0, k, b) for k, b in zip(ks, (0.5, -1.0, 2.0))}
    F = spinal.frames(loop, closed=True, constraints=cons, twist_rule=rule)
    for k, g in cons.items():
        assert np.abs(F[k, :, 0] - g).max() < 1e-12
    # smooth across the seam: the frame turns little from row 199 to row 0
    step = np.einsum("ij,ij->", F[-1], F[0])  # trace of F_{n-1}^T F_0
    assert np.arccos(np.clip((step - 1) / 2, -1, 1)) < 0.2
    with_repeat = spinal.frames(np.r_[loop, loop[:1]], closed=True, constraints=cons,
                                twist_rule=rule)
    assert np.abs(with_repeat[:-1] - F).max() < 1e-12 and np.array_equal(with_repeat[-1], F[0])


def test_frame_constraints_and_bundles():
    x = helix()
    F0 = spinal.frames(x)
    frame = F0[40].copy()
    frame[:, :2] = frame[:, :2] @ np.array([[0.0, -1.0], [1.0, 0.0]])  # turned by 90°
    F = spinal.frames(x, constraints=(np.array([40, 100]), np.stack([frame, F0[100]])))
    assert np.abs(F[40] - frame).max() < 1e-12 and np.abs(F[100] - F0[100]).max() < 1e-12
    y = wiggle()
    both = np.r_[x, y]
    given = [{10: F0[10, :, 1], -5: F0[-5, :, 0]}, None]
    got = spinal.frames(both, lengths=[len(x), len(y)], constraints=given)
    assert np.abs(got[: len(x)] - spinal.frames(x, constraints=given[0])).max() < 1e-14
    assert np.abs(got[len(x) :] - spinal.frames(y)).max() < 1e-14


def test_analytic_curves_take_constraints():
    c = spinal.curves.Helix()
    F0 = spinal.frames(c, u=100)
    F = spinal.frames(c, u=100, constraints={50: F0[50, :, 1]}, twist_rule="min_angular_speed")
    assert np.abs(F[50, :, 0] - F0[50, :, 1]).max() < 1e-12


# ---- guide ------------------------------------------------------------------------------


def test_the_guide_of_an_exact_turned_rmf_is_recovered_to_a_bias_that_shrinks():
    x = wiggle(400)
    F0 = spinal.frames(x)
    s = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(x, axis=0), axis=1))]
    s /= s[-1]
    phi = 1.3 * np.sin(2 * np.pi * s) + 4 * np.pi * s  # two whole turns: needs unwrapping
    g = np.cos(phi)[:, None] * F0[:, :, 0] + np.sin(phi)[:, None] * F0[:, :, 1]
    g = 2.0 * g + 0.7 * F0[:, :, 2]  # a length and a tangential part: only the direction counts
    d2 = np.abs(np.diff(phi, 2)).max()  # φ″ per sample², for the predicted interior bias
    inner, whole = [], []
    weights_ = (1.0, 10.0, 100.0, 1000.0)
    for w in weights_:
        F = spinal.frames(x, guide=g, guide_weight=w)
        alpha = twist_of(F, F0)
        alpha += 2 * np.pi * np.round((phi[0] - alpha[0]) / (2 * np.pi))
        err = np.abs(alpha - phi)
        # away from the ends the bias is about φ″/W; at a free end a boundary layer of about
        # 1/√W samples, where the twist rate relaxes to the RMF's, has a bias ∝ φ′/√W
        cut = 20
        inner.append(err[cut:-cut].max())
        whole.append(err.max())
        assert inner[-1] < 2 * d2 / w, (w, inner[-1], d2)
        assert np.abs(np.einsum("nij,nik->njk", F, F) - np.eye(3)).max() < 1e-12
    inner, whole = np.array(inner), np.array(whole)
    assert np.all(inner[1:] < inner[:-1] / 5), inner
    assert np.all(whole[1:] < whole[:-1] / 2.5), whole
    assert whole[0] < 0.1 and whole[-1] < 1e-3, whole


def test_a_guide_along_the_tangent_falls_back_to_the_rmf():
    x = wiggle()
    F0 = spinal.frames(x)
    assert np.abs(spinal.frames(x, guide=F0[:, :, 2]) - F0).max() < 1e-12
    # a stretch where the guide is the tangent: the twist keeps its rate there (linear)
    phi = np.full(len(x), 1.0)
    phi[100:] = 2.0
    g = np.cos(phi)[:, None] * F0[:, :, 0] + np.sin(phi)[:, None] * F0[:, :, 1]
    g[60:100] = F0[60:100, :, 2]
    alpha = twist_of(spinal.frames(x, guide=g, guide_weight=1e6), F0)
    assert np.abs(alpha[:55] - 1.0).max() < 1e-4 and np.abs(alpha[105:] - 2.0).max() < 1e-4
    sl = alpha[60:100]
    h = np.linalg.norm(np.diff(x[59:101], axis=0), axis=1)
    rate = np.diff(alpha[59:101]) / h
    assert np.all(np.diff(sl) > 0) and rate.std() < 1e-3 * rate.mean()


def test_one_up_vector_levels_the_frames_and_constraints_win():
    u = np.linspace(0, 2 * np.pi, 120, endpoint=False)
    track = np.c_[3 * np.cos(u), 2 * np.sin(u), 0.3 * np.sin(3 * u)]
    F = spinal.frames(track, closed=True, guide=[0, 0, 1], guide_weight=100.0)
    t = F[:, :, 2]
    level = np.array([0, 0, 1.0]) - t[:, 2:] * t  # "up" in the normal plane
    level /= np.linalg.norm(level, axis=1)[:, None]
    assert np.abs(F[:, :, 0] - level).max() < 0.01
    F0 = spinal.frames(track, closed=True)
    v = turned(F0, 30, 0.7)
    F = spinal.frames(track, closed=True, guide=[0, 0, 1], constraints={30: v})
    assert np.abs(F[30, :, 0] - v).max() < 1e-12


def _strand(n=40):
    """A β-strand-like zig-zag (3.3 apart along x, ±0.9 across) on a gentle twist, and a
    smooth field of axes normal to its plane of zig-zag."""
    i = np.arange(n)
    a = 0.05 * i  # the strand twists slowly
    across = np.c_[np.zeros(n), np.cos(a), np.sin(a)]
    x = np.c_[3.3 * i, np.zeros(n), np.zeros(n)] + 0.9 * (-1.0) ** i[:, None] * across
    up = np.c_[np.zeros(n), -np.sin(a), np.cos(a)]
    return x, up


def test_free_guide_signs_follow_axes_as_continuous_frames():
    """guide_sign="free": raw carbonyl-like guides that flip sign at every residue give the
    frames of the consistently signed guide (the angles unwrapped modulo π); with "follow"
    they make the frames corkscrew."""
    x, up = _strand()
    flips = (-1.0) ** np.arange(len(x))
    raw = up * flips[:, None]
    smooth = spinal.frames(x, guide=up)
    free = spinal.frames(x, guide=raw, guide_sign="free")
    np.testing.assert_allclose(free, smooth, atol=1e-12)
    followed = spinal.frames(x, guide=raw)
    assert rotation_angle(followed, smooth).max() > np.radians(45)
    # a consistent guide is the same either way; a guide of one vector too
    np.testing.assert_allclose(spinal.frames(x, guide=up, guide_sign="free"), smooth,
                               atol=1e-12)
    np.testing.assert_allclose(spinal.frames(x, guide=[0, 0, 1], guide_sign="free"),
                               spinal.frames(x, guide=[0, 0, 1]), atol=1e-12)
    # the first usable row keeps its sign: the flipped guide gives the frames turned by π
    turned_half = spinal.frames(x, guide=-raw, guide_sign="free")
    np.testing.assert_allclose(turned_half[:, :, 0], -smooth[:, :, 0], atol=1e-12)
    with pytest.raises(ValueError, match="guide_sign: unknown value 'axis'"):
        spinal.frames(x, guide=raw, guide_sign="axis")


# ---- time ---------------------------------------------------------------------------------


def moving_helix(steps=100, n=200):
    u = np.linspace(0, 6 * np.pi, n)
    b = 0.15 + 0.6 * np.arange(steps) / (steps - 1)
    return np.stack([np.c_[np.cos(u), np.sin(u), bb * u] for bb in b])


def rotation_angle(A, B):
    """Angle of the rotation between frames A[i] and B[i]."""
    tr = np.einsum("nij,nij->n", A, B)
    return np.arccos(np.clip((tr - 1) / 2, -1, 1))


def test_frames_in_time_change_no_more_than_the_curve():
    """A helix of three turns whose pitch b grows over 100 steps. Between steps a frame can
    change by the turn of its tangent plus the change of the RMF's own twist: the RMF turns
    against the Frenet frame by ∫τ ds = 6π b/√(1 + b²) over the helix, and the best single
    turn leaves at most half the change of that total at either end. The frames change by no
    more than that (about 1.1 times it, from the discrete RMF), so nothing jumps, and they
    change about 9x less than frames started afresh from a turned start."""
    P = moving_helix()
    b = 0.15 + 0.6 * np.arange(len(P)) / (len(P) - 1)
    holonomy = 6 * np.pi * b / np.sqrt(1 + b**2)
    F = spinal.frames_in_time(P, previous_twist=False)
    assert F.shape == (100, 200, 3, 3)
    ratios = []
    for k in range(1, len(P)):
        dframe = rotation_angle(F[k], F[k - 1]).max()
        t0, t1 = F[k - 1, :, :, 2], F[k, :, :, 2]
        dtan = np.arccos(np.clip(np.einsum("ij,ij->i", t0, t1), -1, 1)).max()
        bound = dtan + 0.5 * abs(holonomy[k] - holonomy[k - 1])
        ratios.append(dframe / bound)
        # every step is an RMF of its curve
        assert np.abs(F[k, :, :, 2] - spinal.frames(P[k])[:, :, 2]).max() < 1e-15
        assert np.abs(twist_of(F[k], spinal.frames(P[k])).std()) < 1e-12
    assert max(ratios) < 1.1, max(ratios)
    # the same as previous= step by step
    G = [spinal.frames(P[0])]
    for k in range(1, 5):
        G.append(spinal.frames(P[k], previous=G[-1]))
    assert np.abs(np.array(G) - F[:5]).max() < 1e-12
    # continuing a sequence
    again = spinal.frames_in_time(P[50:], previous=F[49], previous_twist=False)
    assert np.abs(again - F[50:]).max() < 1e-12


def test_previous_removes_a_jump_of_the_start():
    P = moving_helix()[:2]
    F0 = spinal.frames(P[0])
    jumped = spinal.frames(P[1], initial=-F0[0, :, 0])  # a start turned by π
    F1 = spinal.frames(P[1], previous=F0)
    assert rotation_angle(jumped, F0).max() > 3.0
    assert rotation_angle(F1, F0).max() < 0.3
    u = np.linspace(0, 2 * np.pi, 100, endpoint=False)
    loop = np.c_[np.cos(u), np.sin(u), 0.3 * np.sin(2 * u)]
    C0 = spinal.frames(loop, closed=True)
    turned_c = C0.copy()
    turned_c[:, :, :2] = -turned_c[:, :, :2]
    assert np.abs(spinal.frames(loop, closed=True, previous=turned_c) - turned_c).max() < 1e-12


# ---- bad input ----------------------------------------------------------------------------


@pytest.mark.parametrize("kwargs,message", [
    ({"constraints": {130: [1, 0, 0]}}, "constraints: row 130 is out of range"),
    ({"constraints": {-121: [1, 0, 0]}}, "constraints: row -121 is out of range"),
    ({"constraints": (np.array([3, 400]), np.eye(3)[:2])}, "constraints: row 400 is out of range"),
    ({"constraints": {3: [1, 2]}}, "constraints: row 3: expected a vector (3,)"),
    ({"constraints": [1, 2]}, "constraints: expected a mapping"),
    ({"constraints": {1.5: [1, 0, 0]}}, "constraints: keys must be integer rows"),
    ({"twist_rule": "curvature"}, "twist_rule: unknown value"),
    ({"guide": np.ones((7, 3))}, "guide: expected shape (3,) or (120, 3)"),
    ({"guide": [1, 0]}, "guide: expected shape (3,) or (120, 3)"),
    ({"guide": [0, 0, 1], "guide_weight": 0.0}, "guide_weight: must be a positive"),
    ({"guide": [0, 0, 1], "guide_tolerance": 2.0}, "guide_tolerance: must be an angle"),
    ({"previous": np.ones((5, 3, 3))}, "previous: expected shape (120, 3, 3)"),
    ({"previous": np.ones((120, 3, 3))}, "previous: row 0 is not a rotation matrix"),
    ({"previous": np.tile(np.eye(3), (120, 1, 1)), "initial": [1, 0, 0]},
     "previous: cannot be combined with initial"),
    ({"constraints": {0: [1, 0, 0]}, "initial": [0, 1, 0]}, "initial: row 0 is also given"),
    ({"constraints": {3: [0, 0, 1], 9: [0, 1, 0]}, "turns": [1, 2]}, "turns: expected one count"),
    ({"constraints": {3: [0, 0, 1]}, "method": "frenet"}, "constraints: is not used by method"),
])
def test_bad_input_is_named(kwargs, message):
    x = helix()
    with pytest.raises((ValueError, TypeError)) as e:
        spinal.frames(x, **kwargs)
    assert message in str(e.value)


def test_a_constraint_parallel_to_the_tangent_is_named():
    x = helix()
    t = spinal.frames(x)[17, :, 2]
    with pytest.raises(ValueError, match="constraints: the vector is zero or parallel to the "
                                         "tangent at row 17"):
        spinal.frames(x, constraints={17: 3 * t})
    y = wiggle()
    with pytest.raises(ValueError, match=r"constraints: row 200 is out of range .* \(curve 1\)"):
        spinal.frames(np.r_[x, y], lengths=[len(x), len(y)], constraints=[None, {200: [1, 0, 0]}])


def test_frames_in_time_bad_input_is_named():
    P = moving_helix(steps=3, n=50)
    with pytest.raises(ValueError, match=r"points_t: expected shape \(T, n, 3\)"):
        spinal.frames_in_time(P[0])
    with pytest.raises(ValueError, match=r"previous: expected shape \(50, 3, 3\)"):
        spinal.frames_in_time(P, previous=np.ones((3, 3, 3)))
    bad = P.copy()
    bad[1, 10, 2] = np.nan
    for twist in (True, False):
        with pytest.raises(ValueError, match="points_t: time step 1: non-finite value .* row "
                                             "10"):
            spinal.frames_in_time(bad, previous_twist=twist)
    with pytest.raises(ValueError, match=r"guide: expected shape \(3,\), \(50, 3\) or"):
        spinal.frames_in_time(P, guide=np.ones((2, 3)))
    with pytest.raises(ValueError, match="previous_weight: must be a positive"):
        spinal.frames_in_time(P, previous_weight=0.0)


def test_bundles_take_guides_and_previous_per_curve():
    x, y = helix(), wiggle()
    both, lengths = np.r_[x, y], [len(x), len(y)]
    gx = np.tile([0.0, 0.0, 1.0], (len(x), 1)) + 0.3 * spinal.frames(x)[:, :, 1]
    gy = np.tile([1.0, 0.0, 0.0], (len(y), 1))
    got = spinal.frames(both, lengths=lengths, guide=np.r_[gx, gy], guide_weight=5.0)
    assert np.abs(got[: len(x)] - spinal.frames(x, guide=gx, guide_weight=5.0)).max() < 1e-14
    assert np.abs(got[len(x) :] - spinal.frames(y, guide=gy, guide_weight=5.0)).max() < 1e-14
    up = spinal.frames(both, lengths=lengths, guide=[0, 0, 1])
    assert np.abs(up[len(x) :] - spinal.frames(y, guide=[0, 0, 1])).max() < 1e-14
    prev = np.r_[spinal.frames(x, initial=[1, 0, 0]), spinal.frames(y, initial=[0, 0, 1])]
    got = spinal.frames(both, lengths=lengths, previous=prev)
    assert np.abs(got[: len(x)] - prev[: len(x)]).max() < 1e-12
    assert np.abs(got[len(x) :] - prev[len(x) :]).max() < 1e-12


def test_steered_frames_refuse_tangents_of_another_length():
    """Found by the randomized harness: per-interval ``turns`` with tangents of the wrong
    length reached the steered path unchecked."""
    x = np.c_[np.cos(np.linspace(0, 1, 5)), np.sin(np.linspace(0, 1, 5)), np.zeros(5)]
    with pytest.raises(ValueError, match="^tangents"):
        spinal.frames(x, np.zeros((0, 3)), turns=[1, 1])


def _jittered_chain(steps=30, n=120, seed=0):
    """A protein-like chain (3.8 apart, turning 70° at every residue about a random axis)
    jittered by 0.1 per time step: its twist changes from step to step."""
    rng = np.random.default_rng(seed)
    d, b, x = np.array([1.0, 0, 0]), np.array([0, 0, 1.0]), [np.zeros(3)]
    for _ in range(n - 1):
        x.append(x[-1] + 3.8 * d)
        a = rng.uniform(0, 2 * np.pi)
        ax = np.cos(a) * b + np.sin(a) * np.cross(d, b)
        ax /= np.linalg.norm(ax)
        d = np.cos(np.radians(70)) * d + np.sin(np.radians(70)) * np.cross(ax, d)
        d /= np.linalg.norm(d)
        b = np.cross(d, ax) / np.linalg.norm(np.cross(d, ax))
    P = [np.array(x)]
    for _ in range(steps - 1):
        P.append(P[-1] + rng.normal(scale=0.1, size=P[-1].shape))
    return np.array(P)


def _excess(F):
    """Per step and sample: how much more the frame turns than its tangent (degrees)."""
    tangent = np.degrees(np.arccos(np.clip(np.einsum("kni,kni->kn", F[1:, :, :, 2],
                                                     F[:-1, :, :, 2]), -1, 1)))
    frame = np.degrees(np.array([rotation_angle(F[k], F[k - 1]) for k in range(1, len(F))]))
    return frame - tangent


def test_frames_in_time_turn_each_sample_no_more_than_its_tangent_by_default():
    """By default each step follows the step before sample by sample (previous_twist): on a
    jittered protein-like chain no frame turns more than 1° beyond its tangent, where one
    turn per step (previous_twist=False) leaves some frames 20° and more beyond theirs."""
    P = _jittered_chain()
    F = spinal.frames_in_time(P)
    assert _excess(F).max() < 1.0, _excess(F).max()
    one_turn = spinal.frames_in_time(P, previous_twist=False)
    assert _excess(one_turn).max() > 20
    # the frames are those of frames(previous=, previous_twist=True) chained
    G = [spinal.frames(P[0])]
    for k in range(1, 4):
        G.append(spinal.frames(P[k], previous=G[-1], previous_twist=True, guide_weight=1000.0))
    np.testing.assert_array_equal(F[:4], np.array(G))
    # a bundle: each curve as alone
    two = np.concatenate([P, P[:, ::-1] + 50], axis=1)
    B = spinal.frames_in_time(two, lengths=[120, 120])
    np.testing.assert_allclose(B[:, :120], F, atol=1e-12)
    # a guide per step: the first step follows its guide, the others their guide and the
    # step before (by default with the guide's weight)
    up = np.broadcast_to([0.0, 0, 1], P.shape)
    Fg = spinal.frames_in_time(P, guide=up, guide_weight=10.0)
    np.testing.assert_array_equal(Fg[0], spinal.frames(P[0], guide=[0, 0, 1],
                                                       guide_weight=10.0))
    np.testing.assert_array_equal(Fg[7], spinal.frames(P[7], guide=[0, 0, 1], guide_weight=10.0,
                                                       previous=Fg[6], previous_weight=10.0))


def test_frames_in_time_of_the_adk_trajectory_do_not_flicker():
    """MDAnalysisTests' adenylate kinase trajectory (98 frames, CA trace): no residue's
    frame turns by 45° or more between frames."""
    mda = pytest.importorskip("MDAnalysis")
    files = pytest.importorskip("MDAnalysisTests.datafiles")
    u = mda.Universe(files.PSF, files.DCD)
    ca = u.select_atoms("name CA")
    P = np.array([ca.positions.astype(float) for _ in u.trajectory])
    F = spinal.frames_in_time(P)
    turns = np.degrees(np.array([rotation_angle(F[k], F[k - 1]) for k in range(1, len(F))]))
    assert turns.max() < 45, turns.max()


def test_axis_guides_take_their_signs_from_the_previous_frames():
    """guide= with previous=: each axis row (guide_sign='free') takes the sign that agrees with
    the previous frames, so a β-strand whose raw carbonyl guides come with the opposite signs
    at the next time step keeps its frames (alone, the first row's sign would turn them all
    by 180°); frames_in_time does the same step by step."""
    n, steps = 30, 12
    rng = np.random.default_rng(4)

    def strand(k):
        s = np.arange(n) * 3.3
        return np.c_[s, 0.9 * (-1.0) ** np.arange(n), 0.05 * k * np.sin(s / 10)]

    def carbonyls():
        return np.c_[np.zeros(n), np.zeros(n), (-1.0) ** np.arange(n)] + rng.normal(0, 0.05, (n, 3))

    def turn(a, b):
        return np.degrees(np.arccos(np.clip((a[:, :, 0] * b[:, :, 0]).sum(1), -1, 1))).max()

    f0 = spinal.frames(strand(0), guide=carbonyls(), guide_sign="free")
    flipped = -carbonyls()
    alone = spinal.frames(strand(1), guide=flipped, guide_sign="free")
    assert turn(f0, alone) > 170
    kept = spinal.frames(strand(1), guide=flipped, guide_sign="free", previous=f0)
    assert turn(f0, kept) < 10
    # the same frames as the guide signed by hand
    signs = np.sign((flipped * f0[:, :, 0]).sum(1))[:, None]
    np.testing.assert_allclose(kept, spinal.frames(strand(1), guide=signs * flipped), atol=1e-12)
    pts = np.stack([strand(k) for k in range(steps)])
    gs = np.stack([carbonyls() * (-1) ** k for k in range(steps)])
    F = spinal.frames_in_time(pts, guide=gs, guide_sign="free")
    assert max(turn(F[k], F[k + 1]) for k in range(steps - 1)) < 15


def _guide_and_previous_case():
    """A helix, a guide "up", and previous frames that follow another guide."""
    t = np.linspace(0, 4 * np.pi, 120)
    h = np.c_[np.cos(t), np.sin(t), 0.2 * t]
    prev = spinal.frames(h, guide=[1.0, 0, 0.3], guide_weight=5.0)
    return h, np.array([0.0, 0, 1]), prev


def test_a_direction_guide_and_previous_tend_to_either_alone():
    """guide= with previous= (guide_sign="follow"): two soft targets of one twist solve. As
    previous_weight → 0 the frames tend to the guide's alone, as guide_weight → 0 to those
    of previous_twist=True alone, both linearly in the vanishing weight (the solution of
    the quadratic is smooth in its weights)."""
    h, up, prev = _guide_and_previous_case()
    guide_only = spinal.frames(h, guide=up)
    previous_only = spinal.frames(h, previous=prev, previous_twist=True, previous_weight=2.0)
    assert np.abs(guide_only - previous_only).max() > 0.5
    gaps = []
    for w in (1e-3, 1e-6, 1e-9):
        a = spinal.frames(h, guide=up, previous=prev, previous_weight=w)
        b = spinal.frames(h, guide=up, guide_weight=w, previous=prev, previous_weight=2.0)
        gaps.append((np.abs(a - guide_only).max(), np.abs(b - previous_only).max()))
    gaps = np.array(gaps)
    assert (gaps[-1] < 1e-8).all(), gaps
    # linear: a thousandth of the weight, a thousandth of the gap
    np.testing.assert_allclose(gaps[1:] / gaps[:-1], 1e-3, rtol=0.01)
    # previous_twist changes nothing once a guide is given
    np.testing.assert_array_equal(
        spinal.frames(h, guide=up, previous=prev, previous_twist=True),
        spinal.frames(h, guide=up, previous=prev))


def test_equal_guide_and_previous_targets_add_their_weights():
    """A guide equal to the previous frames' r columns: the target is the same, its weight
    the sum, so the frames are the guide's alone (or previous_twist's alone) with the
    weights added."""
    h, _, prev = _guide_and_previous_case()
    both = spinal.frames(h, guide=prev[:, :, 0], guide_weight=0.7, previous=prev,
                         previous_weight=1.8)
    np.testing.assert_allclose(both, spinal.frames(h, guide=prev[:, :, 0], guide_weight=2.5),
                               atol=1e-12)
    np.testing.assert_allclose(both, spinal.frames(h, previous=prev, previous_twist=True,
                                                   previous_weight=2.5), atol=1e-12)


def test_guide_and_previous_on_a_line_meet_at_the_weighted_mean_angle():
    """On a straight line (unevenly sampled) the RMF does not turn; a constant guide at the
    angle a from it and previous frames turned by b are met by the constant twist that
    minimises W_g (α − a)² + W_p (α − b)², the weighted mean (W_g a + W_p b)/(W_g + W_p)
    (the twist-rate term vanishes on a constant)."""
    x = np.c_[np.cumsum(np.r_[0, 0.5 + np.random.default_rng(2).random(39)]), np.zeros((40, 2))]
    rmf = spinal.frames(x)
    r0, s0 = rmf[0, :, 0], rmf[0, :, 1]
    a, b, wg, wp = 0.3, 2.0, 1.0, 3.0
    prev = rmf.copy()
    prev[:, :, 0] = np.cos(b) * r0 + np.sin(b) * s0
    prev[:, :, 1] = np.cos(b) * s0 - np.sin(b) * r0
    got = spinal.frames(x, guide=np.cos(a) * r0 + np.sin(a) * s0, guide_weight=wg,
                        previous=prev, previous_weight=wp)
    m = (wg * a + wp * b) / (wg + wp)
    np.testing.assert_allclose(got[:, :, 0], np.tile(np.cos(m) * r0 + np.sin(m) * s0, (40, 1)),
                               atol=1e-12)


def test_guide_and_previous_minimise_the_combined_quadratic():
    """The twist of guide= with previous= on a helix is the minimiser of
    Σ (h̄/h_i)(α_{i+1} − α_i)² + Σ (μ_i/h̄)[W_g sin²∠(g, t_i)(α_i − φ_i)²
    + W_p sin²∠(p_i, t_i)(α_i − ψ_i)²], solved here densely (numpy) from the RMF's angles
    to the guide (φ) and to the previous r columns (ψ)."""
    h, up, prev = _guide_and_previous_case()
    wg, wp = 0.4, 2.5
    got = spinal.frames(h, guide=up, guide_weight=wg, previous=prev, previous_weight=wp)
    rmf = spinal.frames(h)
    r, s, t = rmf[:, :, 0], rmf[:, :, 1], rmf[:, :, 2]

    def angle_and_weight(g):
        p = g - np.einsum("ij,ij->i", g, t)[:, None] * t
        return (np.unwrap(np.arctan2((p * s).sum(1), (p * r).sum(1))),
                1 - np.einsum("ij,ij->i", g, t) ** 2 / np.einsum("ij,ij->i", g, g))

    phi, sg = angle_and_weight(np.tile(up, (len(h), 1)))
    psi, sp = angle_and_weight(prev[:, :, 0])
    psi += 2 * np.pi * np.round((phi[0] - psi[0]) / (2 * np.pi))
    seg = np.linalg.norm(np.diff(h, axis=0), axis=1)
    mean = seg.mean()
    mu = 0.5 * (np.r_[0, seg] + np.r_[seg, 0])
    n = len(h)
    A = np.zeros((n, n))
    for i, e in enumerate(mean / seg):
        A[i, i] += e
        A[i + 1, i + 1] += e
        A[i, i + 1] -= e
        A[i + 1, i] -= e
    cg, cp = wg * sg * mu / mean, wp * sp * mu / mean
    alpha = np.linalg.solve(A + np.diag(cg + cp), cg * phi + cp * psi)
    turn = np.unwrap(np.arctan2((got[:, :, 0] * s).sum(1), (got[:, :, 0] * r).sum(1)))
    turn += 2 * np.pi * np.round((alpha[0] - turn[0]) / (2 * np.pi))
    np.testing.assert_allclose(turn, alpha, atol=1e-10)
    assert np.ptp(alpha) > 1.0  # a twist that varies along the helix


def test_frames_in_time_with_a_direction_guide_keep_to_the_step_before():
    """frames_in_time(guide=) with the default guide_sign: from the second step on each step
    follows its guide and the step before, so a guide that jitters in time moves the frames
    less from step to step than following it alone."""
    t = np.linspace(0, 4 * np.pi, 80)
    h = np.c_[np.cos(t), np.sin(t), 0.2 * t]
    steps = 10
    rng = np.random.default_rng(5)
    P = np.stack([h] * steps)
    g = np.array([0.0, 0, 1]) + rng.normal(0, 0.4, (steps, 80, 3))
    F = spinal.frames_in_time(P, guide=g)
    alone = np.stack([spinal.frames(h, guide=g[k]) for k in range(steps)])

    def step_turn(F):
        return max(np.abs(F[k + 1] - F[k]).max() for k in range(steps - 1))

    assert step_turn(F) < 0.6 * step_turn(alone), (step_turn(F), step_turn(alone))
    np.testing.assert_array_equal(F[0], alone[0])
    np.testing.assert_array_equal(F[3], spinal.frames(h, guide=g[3], previous=F[2]))


def test_guide_is_a_direction_whatever_its_length():
    """T3-02: guide vectors of length 1e300 or 1e-300 (one for all rows, or per row with half
    the rows scaled by 1e200) give the frames of the unit guide; a zero row stays no guide."""
    t = np.linspace(0, 4 * np.pi, 200)
    h = np.c_[np.cos(t), np.sin(t), 0.2 * t]
    ref = spinal.frames(h, guide=[0, 0, 1.0])
    for s in (1e300, 1e155, 1e-160, 1e-300):
        np.testing.assert_array_equal(spinal.frames(h, guide=[0, 0, s]), ref)
    g = np.tile([0.3, 0.1, 1.0], (200, 1))
    scaled = g.copy()
    scaled[::2] *= 1e200
    np.testing.assert_allclose(spinal.frames(h, guide=scaled), spinal.frames(h, guide=g),
                               atol=1e-15)
    assert not np.isnan(scaled).any() and scaled[0, 2] == 1e200  # the input is kept
    holes = g.copy()
    holes[50:60] = 0
    assert np.isfinite(spinal.frames(h, guide=holes)).all()


def test_unsigned_rows_and_turns_that_int64_would_wrap_are_refused():
    """T3-08, T3-09: a uint64 constraint row or turn of 2**64 − 1 (which int64 wraps to −1,
    the last row) and a Python int key of 2**70 are ValueErrors naming the argument."""
    t = np.linspace(0, 4 * np.pi, 50)
    h = np.c_[np.cos(t), np.sin(t), 0.2 * t]
    huge = np.array([2**64 - 1], dtype=np.uint64)
    with pytest.raises(ValueError, match="^constraints: 18446744073709551615 is out of range"):
        spinal.frames(h, constraints=(huge, np.array([[0, 0, 1.0]])))
    with pytest.raises(ValueError, match="^turns: 18446744073709551615 is out of range"):
        spinal.frames(h, turns=huge)
    for key in (2**70, np.uint64(2**64 - 1)):
        with pytest.raises(ValueError, match="^constraints: row .* is out of range"):
            spinal.frames(h, constraints={key: [0, 0, 1.0]})
    # in range, unsigned rows work
    ok = spinal.frames(h, constraints=(np.array([3], dtype=np.uint64), np.array([[0, 0, 1.0]])))
    np.testing.assert_array_equal(ok, spinal.frames(h, constraints={3: [0, 0, 1.0]}))


def test_a_vanishing_guide_weight_tends_to_the_best_constant_turn():
    """T3-05: as guide_weight → 0⁺ the minimisation's solution tends to the best constant
    turn of the RMF towards the guide: the mean of the guide angles φ_i weighted by
    sin²∠(g, t_i) and the samples' half-lengths (computed here from the RMF), at 1e-20 as at
    1e-300 (a tiny weight once fell back to the plain RMF)."""
    t = np.linspace(0, 4 * np.pi, 200)
    h = np.c_[np.cos(t), np.sin(t), 0.2 * t]
    rmf = spinal.frames(h)
    g = np.array([0.0, 0, 1])
    r, s, tt = rmf[:, :, 0], rmf[:, :, 1], rmf[:, :, 2]
    p = g - (tt @ g)[:, None] * tt
    phi = np.unwrap(np.arctan2((p * s).sum(1), (p * r).sum(1)))
    seg = np.linalg.norm(np.diff(h, axis=0), axis=1)
    mu = 0.5 * (np.r_[0, seg] + np.r_[seg, 0])
    w = (1 - (tt @ g) ** 2) * mu
    best = (w * phi).sum() / w.sum()
    for weight in (1e-20, 1e-50, 1e-300):
        f = spinal.frames(h, guide=g, guide_weight=weight)
        turn = np.arctan2((f[:, :, 0] * s).sum(1), (f[:, :, 0] * r).sum(1))
        np.testing.assert_allclose(np.unwrap(turn), best, atol=1e-12)
