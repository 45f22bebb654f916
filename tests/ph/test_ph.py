"""PH cubics (spinal.ph): three single-cubic reference cases R1/R2/R3 and statistics on random
data, computed independently of this code (Mäurer & Jüttler give no reproducible example
data), closed forms against quadrature, measured orders."""

from __future__ import annotations

from math import comb

import numpy as np
import pytest
from scipy.integrate import quad

import spinal
from spinal import ph

S125 = np.sqrt(1.25)
PI = np.pi


def helix_data(t_a, t_b):
    def p(t):
        return np.array([np.cos(t), np.sin(t), 0.5 * t])

    def d(t):
        return np.array([-np.sin(t), np.cos(t), 0.5]) / S125

    return p(t_a), d(t_a), p(t_b), d(t_b)


R3_DATA = ([0.0, 0, 0], [1.0, 0, 0], [1.0, 1, 1], np.array([1.0, 2, 3]) / np.sqrt(14))


def bern(coef, v):
    """Bernstein polynomial with coefficients along axis 0 at v (n,) -> (n, ...)."""
    coef = np.asarray(coef)
    p = coef.shape[0] - 1
    B = np.stack([comb(p, i) * v**i * (1 - v) ** (p - i) for i in range(p + 1)], axis=1)
    return np.tensordot(B, coef, axes=(1, 0))


def derivs(cp, v):
    sp = ph.PHSpline(cp)
    return [sp.evaluate(v, k) for k in (1, 2, 3)]


def random_quats(rng, m):
    return rng.standard_normal((m, 4)), rng.standard_normal((m, 4))


# ---------------------------------------------------------------------------------------
# 1. quaternion representation, invariants, Hermite recovery


def test_from_quaternions_invariants_and_round_trip():
    rng = np.random.default_rng(6)
    A0, A1 = random_quats(rng, 200)
    cp = ph.from_quaternions(A0, A1, rng.standard_normal((200, 3)), scalar_first=True)
    assert ph.is_ph(cp).all()
    inv = ph.invariants(cp)
    v = np.linspace(0, 1, 7)
    for i in range(0, 200, 20):
        A = np.outer(1 - v, A0[i]) + np.outer(v, A1[i])
        d1, d2, d3 = derivs(cp[i], v)
        sigma = np.linalg.norm(d1, axis=1)
        np.testing.assert_allclose(sigma, (A**2).sum(1), rtol=1e-12)          # σ = |A|²
        assert inv["L2"][i] * inv["cos_theta"][i] == pytest.approx(A0[i] @ A1[i] / 3, rel=1e-12)
        assert inv["c"][i] == pytest.approx(((A0[i] - A1[i]) ** 2).sum() / 3, rel=1e-12)
        c = np.cross(d1, d2)
        kappa = np.linalg.norm(c, axis=1) / sigma**3
        tau = np.einsum("ij,ij->i", c, d3) / np.einsum("ij,ij->i", c, c)
        L1, L2, L3 = inv["L1"][i], inv["L2"][i], inv["L3"][i]
        np.testing.assert_allclose(kappa, 6 * L2 * inv["sin_theta"][i] / sigma**2, rtol=1e-10)
        tau_ph = np.sign(inv["delta"][i]) * 6 * np.sqrt(L1 * L3 - L2**2) / sigma**2
        np.testing.assert_allclose(tau, tau_ph, rtol=1e-8)                  # signed (sgn Δ)
        np.testing.assert_allclose(kappa / tau, inv["kappa_over_tau"][i], rtol=1e-8)
    assert np.all(np.abs(inv["k"]) <= 1)
    # preimage -> the same control points, either quaternion convention
    for sf in (False, True):
        B0, B1 = ph.preimage(cp, scalar_first=sf)
        back = ph.from_quaternions(B0, B1, cp[:, 0], scalar_first=sf)
        np.testing.assert_allclose(back, cp, atol=1e-12 * np.abs(cp).max())
    # perturbed inner point: not PH, and the preimage says so
    bad = cp[3].copy()
    bad[1] += [0.0, 0.01, 0.0]
    assert not ph.is_ph(bad)
    with pytest.raises(ValueError, match="control_points: not a PH cubic"):
        ph.preimage(bad)


def test_quaternion_convention_evaluation_and_frenet_frame():
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(10)
    A0, A1 = random_quats(rng, 3)
    cp = ph.from_quaternions(A0, A1, scalar_first=True)
    np.testing.assert_array_equal(ph.from_quaternions(np.roll(A0, -1, 1), np.roll(A1, -1, 1)),
                                  cp)
    # x'(0) = A0 i A0* = |A0|² R(A0) x̂ (scipy's rotation of the unit quaternion)
    R = Rotation.from_quat(A0, scalar_first=True)
    np.testing.assert_allclose(3 * (cp[:, 1] - cp[:, 0]),
                               (A0**2).sum(1)[:, None] * R.apply([1.0, 0, 0]), atol=1e-13)
    # points, derivatives and Frenet frames against spinal.curves.Bezier (power basis)
    v = np.linspace(0, 1, 17)
    for c in cp:
        bz = spinal.curves.Bezier(c)
        for k, f in enumerate((bz.point, bz.d1, bz.d2, bz.d3)):
            np.testing.assert_allclose(ph.evaluate(c, v, k), f(v), atol=1e-13)
        np.testing.assert_allclose(ph.PHSpline(c).frenet(v), bz.frenet(v), atol=1e-12)


def test_hermite_recovers_random_ph_cubics_with_the_signed_equation():
    rng = np.random.default_rng(7)
    A0, A1 = random_quats(rng, 2000)
    cp = ph.from_quaternions(A0, A1, rng.standard_normal((2000, 3)))
    d = np.diff(cp, axis=1)
    t0 = d[:, 0] / np.linalg.norm(d[:, 0], axis=1, keepdims=True)
    t1 = d[:, 2] / np.linalg.norm(d[:, 2], axis=1, keepdims=True)
    cands = ph.hermite(cp[:, 0], t0, cp[:, 3], t1, all=True)
    scale = np.abs(cp).max(axis=(1, 2))
    found = [any(np.abs(c - cp[i]).max() <= 1e-8 * scale[i] for c in cands[i])
             for i in range(2000)]
    assert all(found)
    # the cases where the printed |λ| form fails are common: λ1 < 0 or λ2 > 0
    D = cp[:, 3] - cp[:, 0]
    C = np.einsum("ij,ij->i", t0, t1)
    s2 = 1 - C**2
    lam1 = (np.einsum("ij,ij->i", t0, D) - C * np.einsum("ij,ij->i", t1, D)) / s2
    lam2 = -(np.einsum("ij,ij->i", t1, D) - C * np.einsum("ij,ij->i", t0, D)) / s2
    assert ((lam1 < 0) | (lam2 > 0)).sum() > 100


def test_hermite_random_data_solution_counts_and_validity():
    rng = np.random.default_rng(8)
    n = 20000
    p0, t0, p1, t1 = (rng.standard_normal((n, 3)) for _ in range(4))
    cands = ph.hermite(p0, t0, p1, t1, all=True)
    counts = np.bincount([len(c) for c in cands], minlength=3)
    # an independent implementation: 13,207 / 5,077 / 1,716 of 20,000 (another random stream;
    # 4.5 sigma band)
    np.testing.assert_allclose(counts / n, np.array([13207, 5077, 1716]) / n, atol=0.015)
    for i in range(0, n, 7):
        for c in cands[i]:
            assert ph.is_ph(c, 1e-7)
            np.testing.assert_allclose(c[[0, 3]], [p0[i], p1[i]], atol=1e-12)
            d1, d3 = c[1] - c[0], c[3] - c[2]
            assert np.linalg.norm(np.cross(d1, t0[i])) <= 1e-9 * np.linalg.norm(d1) * 10
            assert d1 @ t0[i] > 0 and d3 @ t1[i] > 0
        lengths = [np.linalg.norm(np.diff(c, axis=0), axis=1).sum() for c in cands[i]]
        assert lengths == sorted(lengths)
    # all=False picks the shortest one and raises where there is none
    i = next(i for i in range(n) if len(cands[i]) == 2)
    np.testing.assert_array_equal(ph.hermite(p0[i], t0[i], p1[i], t1[i]), cands[i][0])
    j = next(j for j in range(n) if len(cands[j]) == 0)
    with pytest.raises(ValueError, match="^p0, t0, p1, t1: no PH cubic"):
        ph.hermite(p0[j], t0[j], p1[j], t1[j])
    with pytest.raises(ValueError, match=f"^p0, t0, p1, t1: row {j}: no PH cubic"):
        ph.hermite(p0, t0, p1, t1)


# ---------------------------------------------------------------------------------------
# 2. reference cases


def test_r1_helix_quarter_turn():
    c = ph.hermite(*helix_data(0, PI / 2), all=True)
    assert len(c) == 2
    np.testing.assert_allclose(c[0], [[1, 0, 0], [1, 0.5858183513, 0.2929091757],
                                      [0.5858183513, 1, 0.4924889878], [0, 1, PI / 4]],
                               atol=1e-9)
    poly = [np.linalg.norm(np.diff(x, axis=0), axis=1).sum() for x in c]
    np.testing.assert_allclose(poly, [1.9287389785, 8.7043191635], atol=1e-9)
    inv = ph.invariants(c[0])
    ref = {"L1": 0.6549648280, "L2": 0.6188093225, "L3": 0.6549648280,
           "cos_theta": 0.7428946482, "sin_theta": 0.6694083519, "delta": 0.0736477323,
           "a": 0.4665249389, "b": 0.1952546940, "c": 0.3905093881, "k": -0.4600007817,
           "kappa_over_tau": 1.9302543506, "sigma_min": 1.6720124429,
           "kappa_max": 0.8890377754}
    for key, val in ref.items():
        assert inv[key] == pytest.approx(val, abs=1e-9), key
    f = ph.angle_fit(c[0], omega_start=PI / 2)
    assert f["omega1"] == pytest.approx(0.8414599690, abs=1e-9)
    assert f["omega1"] - f["omega0"] == pytest.approx(-0.7293363578, abs=1e-9)
    # Ω̇(0) = Ω̇(1) = −0.6553079721 (one-sided 2nd-order differences of the closed form)
    sp = ph.PHSpline(c[0])
    h = 1e-4
    om = sp.angle([0, h, 2 * h, 1 - 2 * h, 1 - h, 1], exact=True, omega_start=PI / 2)
    assert (-3 * om[0] + 4 * om[1] - om[2]) / (2 * h) == pytest.approx(-0.6553079721, abs=1e-7)
    assert (3 * om[5] - 4 * om[4] + om[3]) / (2 * h) == pytest.approx(-0.6553079721, abs=1e-7)


def test_r2_helix_half_turn_takes_the_negative_root():
    c = ph.hermite(*helix_data(0, PI), all=True)
    assert len(c) == 1  # X = 18.09 gives a reversed polygon
    np.testing.assert_allclose(c[0], [[1, 0, 0], [1, 2.0443606702, 1.0221803351],
                                      [-1, 2.0443606702, 0.5486159917], [-1, 0, PI / 2]],
                               atol=1e-9)
    # X < 0: b1 lies beyond the foot n1 = p0 + λ1 t0 (λ1 = 1.7562036828)
    L1 = np.linalg.norm(c[0][1] - c[0][0])
    assert L1 == pytest.approx(2.2856647146, abs=1e-9) and L1 > 1.7562036828
    inv = ph.invariants(c[0])
    assert inv["k"] == pytest.approx(-0.4393997763, abs=1e-9)
    f = ph.angle_fit(c[0], omega_start=PI / 2)
    assert f["omega1"] - f["omega0"] == pytest.approx(-1.4619596135, abs=1e-9)
    sp = ph.PHSpline(c[0])
    h = 1e-4
    om = sp.angle([0, h, 2 * h], exact=True, omega_start=PI / 2)
    assert (-3 * om[0] + 4 * om[1] - om[2]) / (2 * h) == pytest.approx(-0.8750189769, abs=1e-7)


def test_r3_twisted_cubic():
    c = ph.hermite(*R3_DATA, all=True)
    np.testing.assert_allclose(c[0], [[0, 0, 0], [0.3422468518, 0, 0],
                                      [0.6883837533, 0.3767675066, 0.0651512599], [1, 1, 1]],
                               atol=1e-9)
    poly = [np.linalg.norm(np.diff(x, axis=0), axis=1).sum() for x in c]
    np.testing.assert_allclose(poly, [2.0239688758, 7.8596892407], atol=1e-9)
    inv = ph.invariants(c[0])
    ref = {"L1": 0.3422468518, "L2": 0.5157607927, "L3": 1.1659612313, "delta": 0.1066496794,
           "a": 0.5284276736, "b": -0.0038900497, "c": 0.8159342802, "k": -0.6902418139}
    for key, val in ref.items():
        assert inv[key] == pytest.approx(val, abs=1e-9), key
    f = ph.angle_fit(c[0], omega_start=PI / 2)
    assert f["omega1"] - f["omega0"] == pytest.approx(-1.3679101550, abs=1e-9)


# ---------------------------------------------------------------------------------------
# 3. guards and special cases


def test_parallel_tangents():
    # helix, one segment over a full turn: t0 = t1, chord along z, not along t0
    with pytest.raises(ValueError, match="^p0, t0, p1, t1: no PH cubic: end tangents are "
                                         "parallel"):
        ph.hermite(*helix_data(0, 2 * PI))
    assert len(ph.hermite(*helix_data(0, 2 * PI), all=True)) == 0
    # straight data: the uniform line
    c = ph.hermite([1, 2, 3], [2, 0, 0], [4, 2, 3], [1, 0, 0])
    np.testing.assert_allclose(c, [[1, 2, 3], [2, 2, 3], [3, 2, 3], [4, 2, 3]], atol=1e-15)
    assert ph.is_ph(c)


def test_antiparallel_closed_form_and_continuity():
    t0 = np.array([1.0, 0, 0])
    p1 = [0.7, 1, 0.4]
    inv = ph.invariants(ph.hermite([0, 0, 0], t0, p1, -t0))
    assert inv["L1"] == pytest.approx(1.4824751653, abs=1e-9)
    assert inv["L3"] == pytest.approx(0.7824751653, abs=1e-9)
    assert inv["L2"] == pytest.approx(1.0770329614, abs=1e-9)
    assert inv["L2"] ** 2 == pytest.approx(inv["L1"] * inv["L3"], rel=1e-12)  # Tschirnhausen
    assert inv["k"] == 0
    # t1 turned by 1e-4 rad about (0, 0.3, 1): the general formula, close to the closed form
    ax = np.array([0, 0.3, 1.0]) / np.hypot(0.3, 1)
    a = 1e-4
    t1 = -t0 * np.cos(a) + np.cross(ax, -t0) * np.sin(a) + ax * (ax @ -t0) * (1 - np.cos(a))
    c = ph.hermite([0, 0, 0], t0, p1, t1)
    inv2 = ph.invariants(c)
    assert inv2["L1"] == pytest.approx(1.4825610, abs=1e-7)
    assert inv2["L3"] == pytest.approx(0.7825188, abs=1e-7)
    assert abs(inv2["L1"] - inv["L1"]) < 2e-4 and abs(inv2["L3"] - inv["L3"]) < 2e-4
    assert ph.is_ph(c, 1e-7)
    # approaching t1 = −t0 the solution stays PH to round-off with exact end tangents (the
    # λ form of Mäurer & Jüttler's Table 1 was measured to give PH defects up to 2e-4 at
    # 1 + C = 5e-13)
    for a in (1e-2, 1e-5, 1e-6, 1e-7, 1e-9, 0.0):
        t1 = -t0 * np.cos(a) + np.cross(ax, -t0) * np.sin(a)
        c = ph.hermite([0, 0, 0], t0, p1, t1)
        ph.preimage(c, tol=1e-15)                       # raises unless PH to round-off
        d3 = c[3] - c[2]
        np.testing.assert_allclose(d3 / np.linalg.norm(d3), t1, atol=1e-15)
        assert abs(ph.invariants(c)["L1"] - inv["L1"]) < 2 * a + 1e-15
    with pytest.raises(ValueError, match="antiparallel"):
        ph.hermite([0, 0, 0], t0, [2, 0, 0], -t0)


def test_t0_dot_t1_minus_half_is_linear():
    t1 = [-0.5, np.sqrt(3) / 2, 0]
    c = ph.hermite([0, 0, 0], [1, 0, 0], [0.5, 1, 0.3], t1, all=True)
    assert len(c) == 1
    np.testing.assert_allclose(c[0][1:3], [[0.5737699152, 0, 0],
                                           [0.8255600922, 0.4361133794, 0.3]], atol=1e-9)
    ph.preimage(c[0], tol=1e-14)  # PH to round-off (raises otherwise)


def test_coplanar_data_give_planar_cubics_with_constant_frame_angle():
    c = ph.hermite([1, 0, 0], [0, 1, 0], [0, 1, 0], [-1, 0, 0])
    inv = ph.invariants(c)
    assert inv["delta"] == 0 and inv["k"] == 0 and inv["kappa_over_tau"] == np.inf
    f = ph.angle_fit(c, omega_start=0.3)
    assert f["omega1"] == 0.3 and np.all(f["gamma"] == 0)
    sp = ph.PHSpline(c)
    v = np.linspace(0, 1, 11)
    np.testing.assert_allclose(sp.angle(v, exact=True, omega_start=0.3), 0.3, atol=0)
    np.testing.assert_allclose(sp.angle(v, omega_start=0.3, exact=False), 0.3, atol=1e-15)


def test_s_shaped_data_and_bad_input():
    with pytest.raises(ValueError, match="inflection inside the segment"):
        ph.hermite([0, 0, 0], [1, 1, 0], [3, 0, 0], [1, 1.5, 0])
    with pytest.raises(ValueError, match="^t1: zero tangent"):
        ph.hermite([0, 0, 0], [1, 1, 0], [3, 0, 0], [0, 0, 0])
    with pytest.raises(ValueError, match="^p1: equals p0"):
        ph.hermite([0, 0, 0], [1, 1, 0], [0, 0, 0], [1, 0, 0])
    with pytest.raises(ValueError, match="^p0: contains non-finite"):
        ph.hermite([np.nan, 0, 0], [1, 1, 0], [3, 0, 0], [1, 0, 0])
    with pytest.raises(ValueError, match="^t0: expected shape"):
        ph.hermite([0, 0, 0], [1, 1], [3, 0, 0], [1, 0, 0])
    with pytest.raises(TypeError, match="^p1: expected an array of real numbers"):
        ph.hermite([0, 0, 0], [1, 1, 0], "x", [1, 0, 0])
    with pytest.raises(ValueError, match="^control_points: expected shape"):
        ph.is_ph(np.zeros((3, 3)))
    assert not ph.is_ph(np.zeros((4, 3)))  # degenerate polygon: not a PH cubic
    p = np.array([0.0, 0, 0])
    ph.hermite(p, [1, 0, 0], [1, 1, 0], [0, 1, 0])
    assert np.all(p == 0)


# ---------------------------------------------------------------------------------------
# 4. exact RMF angle


def test_exact_angle_equals_quadrature_of_minus_tau_sigma():
    rng = np.random.default_rng(9)
    A0, A1 = random_quats(rng, 5)
    for cp in list(ph.from_quaternions(A0, A1)) + [ph.hermite(*R3_DATA)]:
        sp = ph.PHSpline(cp)

        def tau_sigma(v, sp=sp):
            d1, d2, d3 = (sp.evaluate(v, k)[0] for k in (1, 2, 3))
            c = np.cross(d1, d2)
            return (c @ d3) / (c @ c) * np.linalg.norm(d1)

        v = np.array([0.0, 0.1, 0.37, 0.5, 0.81, 1.0])
        om = sp.angle(v, exact=True, omega_start=0.4)
        ref = [0.4 - quad(tau_sigma, 0, x, epsabs=1e-13, epsrel=1e-13)[0] for x in v]
        np.testing.assert_allclose(om, ref, atol=1e-8)


def test_exact_frame_is_rotation_minimising():
    cp = ph.hermite(*R3_DATA)
    sp = ph.PHSpline(cp)
    v = np.linspace(0.05, 0.95, 19)
    h = 1e-5

    def twist(mode):
        F = (sp.rmf(v, exact=True, omega_start=1.0) if mode == "rmf" else sp.frenet(v))
        Fp = sp.rmf(v + h, exact=True, omega_start=1.0) if mode == "rmf" else sp.frenet(v + h)
        Fm = sp.rmf(v - h, exact=True, omega_start=1.0) if mode == "rmf" else sp.frenet(v - h)
        dr = (Fp[:, :, 0] - Fm[:, :, 0]) / (2 * h)
        return np.einsum("ij,ij->i", dr, F[:, :, 1])

    assert np.abs(twist("rmf")).max() < 1e-8
    assert np.abs(twist("frenet")).min() > 0.1  # the Frenet normal does turn about t
    F = sp.rmf(v, exact=True)
    np.testing.assert_allclose(np.einsum("nij,nik->njk", F, F), np.broadcast_to(np.eye(3),
                                                                                F.shape),
                               atol=1e-14)


# ---------------------------------------------------------------------------------------
# 5. rational approximation of the angle

FIT_CASES = [  # data, I_min, max angle error
    (helix_data(0, PI / 2), 6.686905e-07, 1.826418e-04),
    (helix_data(0, PI), 1.826961e-03, 9.308789e-03),
    (R3_DATA, 6.548026e-06, 6.579721e-04),
]


@pytest.mark.parametrize("data, imin, err", FIT_CASES)
def test_angle_fit_reference_values(data, imin, err):
    cp = ph.hermite(*data)
    sp = ph.PHSpline(cp)
    v = np.linspace(0, 1, 4001)
    errors = []
    for om0, phi in ((PI / 2, None), (PI / 2, 0.0), (2.5, None), (2.5, 0.0)):
        f = ph.angle_fit(cp, omega_start=om0, phi=phi)
        assert f["I_min"] == pytest.approx(imin, rel=1e-5)
        beta, gamma, sg = f["beta"], f["gamma"], f["sg"]
        assert f["lambda"] > f["lambda_star"] and np.all(beta > 0)   # Lemma 11: no pole
        W = bern(gamma, v) / bern(beta, v)
        dW = np.gradient(W, v)
        assert np.all(dW > 0)
        np.testing.assert_allclose(W[[0, -1]], f["w"], atol=1e-14)
        np.testing.assert_allclose(dW[[0, -1]], f["slopes"], rtol=1e-3)
        exact = om0 + (sp.angle(v, exact=True) - sp.angle(0.0, exact=True))          # Ω from Ω(0) = om0
        approx = f["phi"] + 2 * sg * np.arctan(W)
        e = np.abs(approx - exact).max()
        assert e <= np.sqrt(f["I_min"]) * 1.01
        errors.append(e)
        assert np.abs(approx[[0, -1]] - exact[[0, -1]]).max() < 1e-13
    # independent of φ and Ω_start
    np.testing.assert_allclose(errors, err, rtol=1e-4)
    # the spline evaluates the same rational angle
    e = np.abs(sp.angle(v, exact=False, omega_start=PI / 2)
               - sp.angle(v, exact=True, omega_start=PI / 2)).max()
    assert e == pytest.approx(err, rel=1e-4)


def test_angle_fit_lambda_with_the_stated_offsets():
    r1, r3 = ph.hermite(*helix_data(0, PI / 2)), ph.hermite(*R3_DATA)
    f = ph.angle_fit(r1, omega_start=PI / 2)
    assert f["phi"] == pytest.approx(1.2061281479, abs=1e-9)
    assert f["lambda_star"] == pytest.approx(-1.0812735046, abs=1e-9)
    assert f["lambda"] == pytest.approx(-0.1625470092, abs=1e-7)
    f = ph.angle_fit(r1, omega_start=PI / 2, phi=0.0)
    np.testing.assert_allclose(f["w"], [-1, -0.4474483951], atol=1e-9)
    np.testing.assert_allclose(f["slopes"], [0.6553079721, 0.3932536123], atol=1e-9)
    assert f["lambda_star"] == pytest.approx(-0.8140329949, abs=1e-9)
    assert f["lambda"] == pytest.approx(0.1046935005, abs=1e-7)
    for om0, phi, lam in ((PI / 2, 0.0, 2.0416282087), (PI / 2, None, 1.3552588502),
                          (2.5, 0.0, 4.1832877105)):
        assert ph.angle_fit(r3, omega_start=om0, phi=phi)["lambda"] == pytest.approx(lam,
                                                                                     abs=1e-6)


# ---------------------------------------------------------------------------------------
# 6. rational frames and the rational sweep surface


def two_segment_spline():
    a = ph.hermite(*helix_data(0, PI / 2))
    b = ph.hermite(*helix_data(PI / 2, 1.4 * PI))
    return ph.PHSpline(np.stack([a, b]))


def test_rational_frame_from_bernstein_coefficients_is_orthonormal():
    sp = two_segment_spline()
    rf = sp.rational_frames(omega_start=0.7)
    assert rf["f2"].shape == (2, 7, 3) and rf["weight"].shape == (2, 7)
    v = np.linspace(0, 1, 201)
    for i in range(2):
        w = bern(rf["weight"][i], v)[:, None]
        f2, f3 = bern(rf["f2"][i], v) / w, bern(rf["f3"][i], v) / w
        t = bern(rf["tangent"][i], v) / bern(rf["speed"][i], v)[:, None]
        F = np.stack([f2, f3, t], axis=2)
        np.testing.assert_allclose(np.einsum("nij,nik->njk", F, F),
                                   np.broadcast_to(np.eye(3), F.shape), atol=1e-13)
        np.testing.assert_allclose(np.linalg.det(F), 1, atol=1e-13)
        # the same frame as the direct evaluation (sin Ω̃ b + cos Ω̃ n) in the core
        np.testing.assert_allclose(F, sp.rmf(i + v, omega_start=0.7), atol=1e-13)
    # the coefficients are MJ's (29) with the Frenet numerators n̂ = σx″ − σ′x′, b̂ = x′ × x″
    # (Bernstein forms of §3.1) divided by 6L₂sθ
    f = sp.angle_fit(omega_start=0.7)
    for i in range(2):
        d1, d2, d3 = np.diff(sp.control_points[i], axis=0)
        L1, L3 = np.linalg.norm(d1), np.linalg.norm(d3)
        L2c = d1 @ d2 / L1
        bh = np.array([18 * np.cross(d1, d2), 9 * np.cross(d1, d3), 18 * np.cross(d2, d3)])
        nh = np.array([18 * (L1 * d2 - L2c * d1), 9 * (L1 * d3 - L3 * d1),
                       18 * (L2c * d3 - L3 * d2)])
        c, s_ = np.cos(f["phi"][i]), np.sin(f["phi"][i])
        nphi, bphi = c * nh + s_ * bh, c * bh - s_ * nh
        G, B = f["sg"][i] * f["gamma"][i], f["beta"][i]
        c2 = np.array([1, 2, 1])                                 # Bernstein products
        GB2 = 2 * np.convolve(G * c2, B * c2) / [1, 4, 6, 4, 1]
        BG = (np.convolve(B * c2, B * c2) - np.convolve(G * c2, G * c2)) / [1, 4, 6, 4, 1]

        def prod(p4, q2):  # degree 4 (scalar) × degree 2 (vector) -> degree 6
            out = np.zeros((7, 3))
            for a in range(5):
                for b in range(3):
                    out[a + b] += comb(4, a) * comb(2, b) / comb(6, a + b) * p4[a] * q2[b]
            return out

        mj_f2 = prod(GB2, bphi) + prod(BG, nphi)
        scale = 6 * np.linalg.norm(np.cross(d1, d2)) / L1
        np.testing.assert_allclose(mj_f2 / scale, rf["f2"][i], atol=1e-13)
    # continuous across the joint, and equal to the exact RMF there
    F = sp.rmf([1.0 - 1e-12, 1.0], omega_start=0.7)
    np.testing.assert_allclose(F[0], F[1], atol=1e-10)
    E = sp.rmf([0.0, 1.0, 2.0], omega_start=0.7, exact=True)
    np.testing.assert_allclose(sp.rmf([0.0, 1.0, 2.0], omega_start=0.7), E, atol=1e-13)
    # frames differ from exact inside by the fitted angle error only
    v = np.linspace(0, 2, 401)
    ang = np.arccos(np.clip(np.einsum("ij,ij->i", sp.rmf(v)[:, :, 0],
                                      sp.rmf(v, exact=True)[:, :, 0]), -1, 1))
    assert 1e-6 < ang.max() <= np.sqrt(sp.angle_fit()["I_min"].max()) * 1.01


def test_rational_sweep_surface_equals_the_swept_section():
    sp = two_segment_spline()
    ctrl = np.array([[1.0, 0], [1, 1], [0, 1]]) * 0.2     # quarter circle, radius 0.2
    wts = np.array([1, np.sqrt(0.5), 1])
    net = sp.surface(ctrl, wts, omega_start=0.7)
    assert net.shape == (2, 10, 3, 4)
    u = np.linspace(0, 1, 9)
    v = np.linspace(0, 1, 13)
    Bu = np.stack([comb(2, j) * u**j * (1 - u) ** (2 - j) for j in range(3)], axis=1)
    Bv = np.stack([comb(9, i) * v**i * (1 - v) ** (9 - i) for i in range(10)], axis=1)
    cu = (Bu * wts) @ ctrl / (Bu @ wts)[:, None]
    np.testing.assert_allclose(np.linalg.norm(cu, axis=1), 0.2, rtol=1e-14)
    for i in range(2):
        h = np.einsum("vi,uj,ijk->vuk", Bv, Bu, net[i])
        surf = h[..., :3] / h[..., 3:]
        F = sp.rmf(i + v, omega_start=0.7)
        ref = (sp.evaluate(i + v)[:, None, :] + cu[None, :, 0, None] * F[:, None, :, 0]
               + cu[None, :, 1, None] * F[:, None, :, 1])
        np.testing.assert_allclose(surf, ref, atol=1e-13)
    # the printed (42) sign (+2W n̂ in the c₃ bracket) would not give this: f₃ is checked
    # against t × f₂ in the orthonormality test above.


def test_spline_sweep_mesh():
    sp = two_segment_spline()
    a = np.linspace(0, 2 * PI, 12, endpoint=False)
    mesh = sp.sweep(0.1 * np.c_[np.cos(a), np.sin(a)], n_per_segment=32)
    assert isinstance(mesh, spinal.Mesh) and mesh.is_watertight
    assert mesh.vertices.shape == ((2 * 32 + 1) * 12, 3)
    # ring 0 lies in the normal plane at the start, radius 0.1
    ring = mesh.vertices[:12] - sp.evaluate(0.0)
    np.testing.assert_allclose(np.linalg.norm(ring, axis=1), 0.1, rtol=1e-12)
    np.testing.assert_allclose(ring @ sp.rmf(0.0)[0][:, 2], 0, atol=1e-14)


# ---------------------------------------------------------------------------------------
# 7. curves -> G¹ PH splines: independently computed tables and the measured orders

HELIX = spinal.curves.Helix(1.0, 0.5)
TWISTED = spinal.curves.Polynomial([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
INFLECTION = spinal.curves.Polynomial([[0, 0, 0], [1, 0, 0], [0, 0, 0], [0, 1, 0],
                                       [0, 0, 0.2]], domain=(-1, 1))


def frame_measures(sp, r=0.1, nv=2001):
    """max |Ω̃ − Ω|, max Î, max |O| for a circular section of radius r (Ω_start = π/2).

    O = δ r/√(μ̃²σ² + δ²r²) at the worst point of the circle, μ̃ = 1 − κr, with
    δ = Ω̃′ − Ω′ from the fitted W (Bernstein form) and the closed-form Ω′."""
    f = sp.angle_fit(omega_start=PI / 2)
    inv = ph.invariants(sp.control_points)
    v = np.linspace(0, 1, nv)
    amax = omax = 0.0
    for i in range(sp.segments):
        s = i + v
        amax = max(amax, np.abs(sp.angle(s, exact=False, omega_start=PI / 2)
                                - sp.angle(s, exact=True, omega_start=PI / 2)).max())
        b, g = f["beta"][i], f["gamma"][i]
        N, D = bern(g, v), bern(b, v)
        dN = 2 * ((g[1] - g[0]) * (1 - v) + (g[2] - g[1]) * v)
        dD = 2 * ((b[1] - b[0]) * (1 - v) + (b[2] - b[1]) * v)
        W, dW = N / D, (dN * D - N * dD) / D**2
        k, a, bb, c = inv["k"][i], inv["a"][i], inv["b"][i], inv["c"][i]
        delta = f["sg"][i] * 2 * dW / (1 + W * W) - 2 * k * c * a / (a * a + (c * v - bb) ** 2)
        d1, d2 = sp.evaluate(s, 1), sp.evaluate(s, 2)
        sig = np.linalg.norm(d1, axis=1)
        kap = np.linalg.norm(np.cross(d1, d2), axis=1) / sig**3
        O = np.abs(delta) * r / np.sqrt((1 - kap * r) ** 2 * sig**2 + delta**2 * r**2)
        omax = max(omax, O.max())
    return amax, f["I_min"].max(), omax


def end_vs_true_rmf(sp, curve):
    """Angle between the spline's rational RMF and the curve's true RMF at the end, both
    started from the spline's start frame (r0 = b of the first cubic)."""
    r0 = sp.rmf(0.0, omega_start=PI / 2)[0][:, 0]
    lo, hi = curve.domain
    if isinstance(curve, spinal.curves.Helix):
        fr = curve.frenet(np.array([lo]))[0]
        R = curve.rmf(np.array([lo, hi]), angle=np.arctan2(r0 @ fr[:, 1], r0 @ fr[:, 0]))[-1]
    else:
        R = spinal.frames(curve, u=20001, method="rk4", initial=r0)[-1]
    E = sp.rmf(float(sp.segments), omega_start=PI / 2)[0]
    np.testing.assert_allclose(R[:, 2], E[:, 2], atol=1e-14)  # same end tangent
    return np.arctan2(np.linalg.norm(np.cross(R[:, 0], E[:, 0])), R[:, 0] @ E[:, 0])


def test_helix_spline_table_and_orders():
    with pytest.raises(ValueError, match=r"^segments: interval 0 \[0, 6.28319\]: no PH cubic: "
                                         "the end tangents are parallel"):
        ph.fit(HELIX, segments=1)
    dev = {N: ph.fit(HELIX, segments=N).deviation.max() for N in (2, 3, 4, 8, 16, 32, 64)}
    ref = {2: 5.333e-1, 3: 6.275e-2, 4: 1.778e-2, 8: 1.017e-3, 16: 6.233e-5, 32: 3.877e-6,
           64: 2.420e-7}
    for N, val in ref.items():
        assert dev[N] == pytest.approx(val, rel=1e-3), N
    table = {4: (1.826e-4, 6.687e-7, 8.721e-5, 2.233e-2), 8: (5.199e-6, 5.387e-10, 4.609e-6,
                                                             1.234e-3),
             16: (1.589e-7, 5.026e-13, 2.766e-7, 7.496e-5),
             32: (4.938e-9, 4.853e-16, 1.711e-8, 4.651e-6)}
    ends = {}
    for N, (ang, imax, o, end) in table.items():
        sp = ph.fit(HELIX, segments=N)
        got = frame_measures(sp)
        np.testing.assert_allclose(got, (ang, imax, o), rtol=1e-3)
        ends[N] = end_vs_true_rmf(sp, HELIX)
        assert ends[N] == pytest.approx(end, rel=1e-3)
    for a, b in ((4, 8), (8, 16), (16, 32), (32, 64)):
        assert 12 < dev[a] / dev[b] < 20                     # spine h⁴
    for a, b in ((8, 16), (16, 32)):
        assert 12 < ends[a] / ends[b] < 20                   # frame vs true RMF h⁴


def test_twisted_cubic_spline_table_and_orders():
    ref = {1: 1.2666e-2, 2: 1.2754e-3, 4: 1.4994e-4, 8: 1.1741e-5, 16: 7.7890e-7,
           32: 4.9421e-8, 64: 3.1005e-9}
    dev = {N: ph.fit(TWISTED, segments=N).deviation.max() for N in ref}
    for N, val in ref.items():
        assert dev[N] == pytest.approx(val, rel=1e-3), N
    for a, b in ((8, 16), (16, 32), (32, 64)):
        assert 12 < dev[a] / dev[b] < 20
    table = {2: (9.189e-5, 1.512e-7, 1.385e-4, 5.175e-4), 4: (5.089e-6, 5.044e-10, 1.726e-5,
                                                             3.471e-5),
             8: (1.857e-7, 6.832e-13, 1.290e-6, 2.202e-6),
             16: (6.033e-9, 7.238e-16, 8.422e-8, 1.371e-7)}
    ends = {}
    for N, (ang, imax, o, end) in table.items():
        sp = ph.fit(TWISTED, segments=N)
        np.testing.assert_allclose(frame_measures(sp), (ang, imax, o), rtol=1e-3)
        ends[N] = end_vs_true_rmf(sp, TWISTED)
        # the true RMF is RK4 on 20001 samples: ~1e-9 of its own error
        assert ends[N] == pytest.approx(end, rel=1e-3 if N < 16 else 1e-2)
    assert 12 < ends[4] / ends[8] < 20 and 12 < ends[8] / ends[16] < 20


def test_inflection_curve_order_three_and_errors():
    dev = [ph.fit(INFLECTION, segments=N).deviation.max() for N in (2, 4, 8, 16, 32, 64)]
    np.testing.assert_allclose(dev, [5.781e-2, 7.158e-3, 8.497e-4, 1.056e-4, 1.320e-5,
                                     1.649e-6], rtol=1e-3)
    ratios = np.array(dev[:-1]) / dev[1:]
    assert np.all((ratios > 6) & (ratios < 10))              # h³ next to the inflection knot
    for N in (3, 5, 9, 17, 33):                              # inflection inside the middle
        with pytest.raises(ValueError, match=rf"^segments: interval {N // 2} .*inflection"):
            ph.fit(INFLECTION, segments=N)
    lopsided = spinal.curves.Polynomial(INFLECTION.coefficients, domain=(-1, 1.1))
    for N in (3, 5, 16, 64):
        with pytest.raises(ValueError, match="no PH cubic"):
            ph.fit(lopsided, segments=N)
    for N in (2, 4, 6, 7, 8, 32):
        ph.fit(lopsided, segments=N)
    with pytest.raises(ValueError, match=r"^knots: interval 1 \[-0.5, 0.5\]"):
        ph.fit(INFLECTION, knots=[-1, -0.5, 0.5, 1])


def test_nearly_straight_curve_keeps_order_four():
    # κ ≈ 2e-4: fine segments have nearly parallel end tangents (|t0 − t1| ~ 1e-5), where the
    # printed λ form loses ~10 digits (it gives 1.8e-8 at N = 16); the mean-leg form does not
    gentle = spinal.curves.Polynomial([[0, 0, 0], [1, 0, 0], [0, 1e-4, 0], [0, 0, 1e-4]])
    dev = [ph.fit(gentle, segments=N).deviation.max() for N in (4, 8, 16, 32)]
    ratios = np.array(dev[:-1]) / dev[1:]
    assert np.all((ratios > 12) & (ratios < 20)), dev
    sp = ph.fit(gentle, tol=1e-12)
    assert sp.deviation.max() <= 1e-12


def test_rmf_on_nearly_straight_twisting_cubics_is_accurate():
    # κ ≈ 2e-4 but τ ≈ 3: on fine segments the Frenet frame and Ω are both ill-conditioned
    # (Frenet from x′ × x″ gave 1e-5 rad errors at N = 256); via the Euler–Rodrigues frame of
    # the preimage the RMF matches double reflection on the spline's own samples
    gentle = spinal.curves.Polynomial([[0, 0, 0], [1, 0, 0], [0, 1e-4, 0], [0, 0, 1e-4]])
    sp = ph.fit(gentle, segments=256)
    assert np.all(np.abs(ph.invariants(sp.control_points)["k"]) > 0.999)  # nearly straight
    s = np.linspace(0, 256, 256 * 40 + 1)
    T = sp.evaluate(s, 1)
    T /= np.linalg.norm(T, axis=1)[:, None]
    for exact in (True, False):
        F = sp.rmf(s, exact=exact, initial=[0, 1, 0])
        R = spinal.frames(sp.evaluate(s), T, initial=F[0][:, 0])
        err = np.arctan2(np.einsum("ij,ij->i", np.cross(R[:, :, 0], F[:, :, 0]), T),
                         np.einsum("ij,ij->i", R[:, :, 0], F[:, :, 0]))
        assert np.abs(err).max() < 1e-12
    # the Bernstein form of the rational frame is as accurate there
    rf = sp.rational_frames(initial=[0, 1, 0])
    v = np.linspace(0, 1, 9)
    F = sp.rmf((np.arange(0, 256, 15)[:, None] + v).ravel(), initial=[0, 1, 0])
    F = F.reshape(-1, 9, 3, 3)
    for j, i in enumerate(range(0, 256, 15)):
        w = bern(rf["weight"][i], v)[:, None]
        np.testing.assert_allclose(bern(rf["f2"][i], v) / w, F[j, :, :, 0], atol=1e-13)
        np.testing.assert_allclose(bern(rf["f3"][i], v) / w, F[j, :, :, 1], atol=1e-13)


def test_adaptive_fit():
    for tol in (1e-3, 1e-6):
        sp = ph.fit(INFLECTION, tol=tol)
        assert sp.deviation.max() <= tol and np.abs(sp.knots).min() < 1e-12
        assert np.diff(sp.knots).min() > 1e-6
        assert sp.knots[0] == -1 and sp.knots[-1] == 1
        # G¹: shared points and unit tangents at the joints
        P = sp.control_points
        np.testing.assert_array_equal(P[1:, 0], P[:-1, 3])
        d_in = P[:-1, 3] - P[:-1, 2]
        d_out = P[1:, 1] - P[1:, 0]
        np.testing.assert_allclose(d_in / np.linalg.norm(d_in, axis=1)[:, None],
                                   d_out / np.linalg.norm(d_out, axis=1)[:, None], atol=1e-14)
    coarse = ph.fit(INFLECTION, tol=1e-3)
    # the independent deviation: closest points of the curve to dense spline points
    x = coarse.points(64)
    u = np.linspace(-1, 1, 200001)
    c = INFLECTION.point(u)
    from scipy.spatial import cKDTree
    d, _ = cKDTree(c).query(x)
    assert d.max() <= 1e-3 * 1.001
    # sampled input: knots are rows, the inflection row 200 is one of them
    u = np.linspace(-1, 1, 401)
    sp = ph.fit(INFLECTION.point(u), tol=1e-5)
    assert sp.deviation.max() <= 1e-5 and 200 in sp.knots
    assert np.all(sp.knots == np.round(sp.knots))
    # 9 samples: the estimated end tangent is too poor for the first one-step interval,
    # which cannot be split; with exact tangents every one-step interval is accepted
    u = np.linspace(-1, 1, 9)
    with pytest.raises(ValueError, match=r"^tol: interval \[0, 1\] cannot be split further: "
                                         "no PH cubic"):
        ph.fit(INFLECTION.point(u), tol=1e-9)
    sp = ph.fit(INFLECTION.point(u), tangents=INFLECTION.d1(u), tol=1e-9)
    np.testing.assert_array_equal(sp.knots, np.arange(9))


def test_fit_bad_input():
    with pytest.raises(TypeError, match="^tol, segments, knots"):
        ph.fit(HELIX, tol=1e-3, segments=3)
    with pytest.raises(ValueError, match="^segments: must be >= 1"):
        ph.fit(HELIX, segments=0)
    with pytest.raises(ValueError, match="^knots: expected a strictly increasing"):
        ph.fit(HELIX, knots=[0, 2, 1])
    with pytest.raises(ValueError, match="^tol: must be positive"):
        ph.fit(HELIX, tol=-1)
    with pytest.raises(ValueError, match="^curve: contains non-finite"):
        ph.fit(np.array([[0, 0, 0], [1, np.nan, 0], [2, 0, 1]]))
    with pytest.raises(ValueError, match="^curve: expected an array of shape"):
        ph.fit(np.zeros((5, 2)))
    with pytest.raises(ValueError, match="^s: values must be finite"):
        ph.fit(HELIX, segments=4).evaluate(4.5)
    with pytest.raises(ValueError, match="^initial: is zero"):
        ph.fit(HELIX, segments=4).rmf(initial=HELIX.tangent(0.0)[0])
    with pytest.raises(ValueError, match="^control_points: cubic 1 is not a PH cubic"):
        P = ph.fit(HELIX, segments=4).control_points.copy()
        P[1, 1] += 0.01
        ph.PHSpline(P)


def test_fit_segments_bounded():
    # the bound comes before any allocation (10**7 intervals exhausted the memory)
    with pytest.raises(ValueError, match="^segments: must be <= 100000, got 10000000"):
        ph.fit(HELIX, segments=10**7)
    with pytest.raises(ValueError, match="^segments: must be <= 100000"):
        ph.fit(HELIX.point(np.linspace(0, 1, 5)), segments=100_001)


def test_value_checks_in_the_core_name_the_argument():
    sp = ph.fit(HELIX, segments=4)
    P = sp.control_points
    with pytest.raises(ValueError, match=r"^control_points: contains non-finite values "
                                         r"\(at index \(0, 2, 1\)\)"):
        bad = P.copy()
        bad[0, 2, 1] = np.inf
        ph.is_ph(bad)
    with pytest.raises(ValueError, match="^tol: must be non-negative"):
        ph.is_ph(P, tol=-1.0)
    with pytest.raises(ValueError, match="^control_points: contains non-finite"):
        ph.invariants(np.full((4, 3), np.nan))
    with pytest.raises(ValueError, match="^control_points: cubic 0 has a zero-length leg"):
        ph.invariants(np.zeros((4, 3)))
    with pytest.raises(ValueError, match="^A1: contains non-finite"):
        ph.from_quaternions([1, 0, 0, 0], [np.nan, 0, 0, 1])
    with pytest.raises(ValueError, match="^start: contains non-finite"):
        ph.from_quaternions([1, 0, 0, 0], [0, 0, 0, 1], start=[0, np.inf, 0])
    with pytest.raises(ValueError, match="^control_points: cubic 1: not a PH cubic"):
        bad = P.copy()
        bad[1, 1] += 0.01
        ph.preimage(bad)
    with pytest.raises(ValueError, match="^knots: must be strictly increasing"):
        ph.PHSpline(P, knots=[0, 1, 3, 2, 4])
    with pytest.raises(ValueError, match="^knots: contains non-finite"):
        ph.PHSpline(P, knots=[0, 1, np.nan, 2, 4])
    with pytest.raises(ValueError, match="^control_points: no cubics"):
        ph.PHSpline(np.zeros((0, 4, 3)))
    with pytest.raises(ValueError, match="^control_points: cubic 2 does not start"):
        bad = P.copy()
        bad[2:] += 1.0
        ph.PHSpline(bad)
    with pytest.raises(ValueError, match="^omega_start: must be finite"):
        sp.rmf(omega_start=np.nan)
    with pytest.raises(ValueError, match="^omega_start: must be finite"):
        ph.angle_fit(P[0], omega_start=np.inf)
    with pytest.raises(ValueError, match="^phi: must be finite"):
        ph.angle_fit(P[0], phi=np.nan)
    with pytest.raises(ValueError, match="^derivative: must be 0, 1, 2 or 3, got 4"):
        sp.evaluate(0.5, 4)
    with pytest.raises(ValueError, match="^derivative: must be >= 0"):
        sp.evaluate(0.5, -1)
    with pytest.raises(ValueError, match="^control_points: contains non-finite"):
        ph.evaluate(np.full((4, 3), np.nan), 0.5)


def test_orthogonality_measure_on_the_swept_surface():
    """|O| = |<s_u, s_v>|/(|s_u||s_v|) from finite differences of the surface swept with the
    rational frame (helix, N = 4, circle of radius 0.1): the table's 8.721e-5, computed
    here without the closed form used in frame_measures."""
    sp = ph.fit(HELIX, segments=4)
    r, h = 0.1, 1e-3
    al = np.linspace(0, 2 * PI, 361)[:-1]
    ca, sa = np.cos(al)[None, :, None], np.sin(al)[None, :, None]
    worst = 0.0
    for i in range(4):
        v = np.linspace(2 * h, 1 - 2 * h, 801)

        def surf(vv, i=i):
            F = sp.rmf(i + vv, omega_start=PI / 2)
            x = sp.evaluate(i + vv)[:, None, :]
            return x + r * (ca * F[:, None, :, 0] + sa * F[:, None, :, 1]), F

        sv = (-surf(v + 2 * h)[0] + 8 * surf(v + h)[0] - 8 * surf(v - h)[0]
              + surf(v - 2 * h)[0]) / (12 * h)
        F = surf(v)[1]
        su = r * (-sa * F[:, None, :, 0] + ca * F[:, None, :, 1])
        O = np.abs((su * sv).sum(-1)) / (np.linalg.norm(su, axis=-1)
                                         * np.linalg.norm(sv, axis=-1))
        worst = max(worst, O.max())
    assert worst == pytest.approx(8.721e-5, rel=1e-3)


def test_spline_with_a_straight_cubic_carries_the_frame():
    a = ph.hermite([0, 0, 0], [1, 0, 0], [1, 1, 0.2], [0, 1, 0])
    b = np.array([[1, 1, 0.2], [1, 5 / 3, 0.2], [1, 7 / 3, 0.2], [1, 3, 0.2]])
    c = ph.hermite([1, 3, 0.2], [0, 1, 0], [0, 4, 0.5], [-1, 0, 0.3])
    sp = ph.PHSpline(np.stack([a, b, c]))
    assert ph.is_ph(b) and ph.angle_fit(b)["straight"]
    s = np.linspace(0, 3, 601)
    for exact in (True, False):
        F = sp.rmf(s, exact=exact, initial=[0, 0, 1])
        np.testing.assert_allclose(np.einsum("nij,nik->njk", F, F),
                                   np.broadcast_to(np.eye(3), F.shape), atol=1e-14)
        assert F[0][:, 0] @ [0, 0, 1] == pytest.approx(1.0, abs=1e-15)  # r0 = initial
        on_line = F[(s >= 1) & (s <= 2)]
        np.testing.assert_allclose(on_line[:, :, 0], on_line[:1, :, 0].repeat(len(on_line), 0),
                                   atol=1e-14)                            # r carried
        J = sp.rmf([1 - 1e-9, 1.0, 2 - 1e-9, 2.0], exact=exact, initial=[0, 0, 1])
        np.testing.assert_allclose(J[0], J[1], atol=1e-7)
        np.testing.assert_allclose(J[2], J[3], atol=1e-7)
    rf = sp.rational_frames(initial=[0, 0, 1])
    v = np.linspace(0, 1, 11)
    for i in range(3):
        w = bern(rf["weight"][i], v)[:, None]
        np.testing.assert_allclose(bern(rf["f2"][i], v) / w,
                                   sp.rmf(i + v, initial=[0, 0, 1])[:, :, 0], atol=1e-13)


def test_garbage_never_gives_nan_and_inputs_are_copied():
    rng = np.random.default_rng(11)
    accepted = 0
    for _ in range(1500):
        m = int(rng.integers(1, 4))
        if rng.random() < 0.5:
            P = rng.integers(-2, 3, size=(m, 4, 3)).astype(float)
        else:  # small integer preimages: planar, straight, cusps, zero legs
            A = rng.integers(-1, 2, size=(m, 2, 4)).astype(float)
            P = ph.from_quaternions(A[:, 0], A[:, 1])
        P[1:] += (np.cumsum(P[:-1, 3] - P[:-1, 0], axis=0) - P[1:, 0] + P[0, 0])[:, None]
        try:
            sp = ph.PHSpline(P)
        except ValueError as e:
            assert str(e).startswith("control_points: ")
            continue
        accepted += 1
        s = np.linspace(0, m, 23)
        outs = [sp.evaluate(s, 2), sp.frenet(s), sp.rmf(s), sp.rmf(s, exact=True),
                sp.angle(s), sp.surface([[1, 0], [0, 1]]), *sp.rational_frames().values()]
        assert all(np.isfinite(o).all() for o in outs)
    assert accepted > 200
    P = ph.fit(HELIX, segments=3).control_points.copy()
    sp = ph.PHSpline(P)
    P[:] = 0
    assert np.abs(sp.control_points).max() > 0 and not sp.control_points.flags.writeable
    with pytest.raises(ValueError, match="^control_points: not a PH cubic"):
        ph.angle_fit(np.eye(4, 3))
    with pytest.raises(ValueError, match="^curve: bad Hermite data"):
        ph.fit(np.array([[0.0, 0, 0], [1, 0, 0], [1, 0, 0], [2, 1, 0]]),
               tangents=np.ones((4, 3)), segments=3)


def test_from_quaternions_orders_starts_and_empty_input():
    """(x, y, z, w) rows give the cubics of the same quaternions scalar first, one start
    serves every row as the same start repeated does, and no rows give no cubics. The
    control points are checked against the closed form b₁ = b₀ + A0 i A0*/3 …"""
    rng = np.random.default_rng(7)
    A0, A1 = random_quats(rng, 50)                       # scalar first
    xyzw = lambda q: np.roll(q, -1, axis=1)
    p = np.array([1.0, -2.0, 0.5])
    a = ph.from_quaternions(A0, A1, p, scalar_first=True)
    b = ph.from_quaternions(xyzw(A0), xyzw(A1), np.tile(p, (50, 1)))
    np.testing.assert_array_equal(a, b)

    def qmul(u, v):  # Hamilton product, scalar first
        w0, x0, y0, z0 = u
        w1, x1, y1, z1 = v
        return np.array([w0 * w1 - x0 * x1 - y0 * y1 - z0 * z1,
                         w0 * x1 + x0 * w1 + y0 * z1 - z0 * y1,
                         w0 * y1 - x0 * z1 + y0 * w1 + z0 * x1,
                         w0 * z1 + x0 * y1 - y0 * x1 + z0 * w1])

    def aib(u, v):  # vector part of u i v*
        return qmul(qmul(u, [0.0, 1.0, 0.0, 0.0]), v * [1, -1, -1, -1])[1:]

    for i in (0, 17, 49):
        b1 = p + aib(A0[i], A0[i]) / 3
        b2 = b1 + (aib(A0[i], A1[i]) + aib(A1[i], A0[i])) / 6
        b3 = b2 + aib(A1[i], A1[i]) / 3
        np.testing.assert_allclose(a[i], [p, b1, b2, b3], rtol=0, atol=1e-12)
    assert ph.from_quaternions(np.zeros((0, 4)), np.zeros((0, 4))).shape == (0, 4, 3)
    with pytest.raises(ValueError, match=r"^start: expected \(3,\) or \(50, 3\)"):
        ph.from_quaternions(A0, A1, np.zeros((2, 3)))
