"""Frenet frames: exact where the curvature is non-zero, continuous fill where it vanishes."""

import numpy as np
from conftest import orthonormality_error

import spinal
from spinal.curves import Bezier, Helix


def test_frenet_matches_analytic_frenet():
    h = Helix(1.0, 0.4, turns=2)
    u = h.parameters(400)
    exact = h.frenet(u)
    F = spinal.frames(h, u=u, method="frenet")
    np.testing.assert_allclose(F, exact, atol=1e-14)
    # from points only: N from the circle through neighbouring samples, 2nd order inside
    # (1st order at the two end samples, where the circle is one-sided)
    errs, ends = [], []
    for n in (201, 401, 801):
        d = np.abs(spinal.frames(h.sample(n), method="frenet") - h.frenet(h.parameters(n)))
        errs.append(d[1:-1].max())
        ends.append(d[[0, -1]].max())
    assert all(errs[i] / errs[i + 1] > 3.8 for i in range(2)), errs  # (16 on a helix)
    assert all(1.8 < ends[i] / ends[i + 1] < 2.2 for i in range(2)), ends


def test_frenet_fill_across_straight_run_is_continuous_and_linear():
    # quarter circle about c = (0, 1, 0) ending at the origin heading +x, a straight run
    # along +x (κ = 0), then a quarter circle about (2, 0, 1) bending up into z
    c = np.array([0.0, 1.0, 0.0])
    phi = np.linspace(-np.pi / 2, 0, 60)
    arc1 = c + np.c_[np.sin(phi), -np.cos(phi), 0 * phi]
    run = np.c_[np.linspace(0, 2, 41)[1:-1], np.zeros(39), np.zeros(39)]
    b = np.linspace(0, np.pi / 2, 60)
    arc2 = np.c_[2 + np.sin(b), np.zeros_like(b), 1 - np.cos(b)]
    x = np.r_[arc1, run, arc2]
    F = spinal.frames(x, method="frenet")
    assert np.all(np.isfinite(F)) and orthonormality_error(F) < 1e-12
    # on the first arc N points to its centre (0, 1, 0)... within the estimate accuracy
    n1 = (c - arc1[5:-5]) / np.linalg.norm(c - arc1[5:-5], axis=1, keepdims=True)
    assert np.abs(F[5 : len(arc1) - 5, :, 0] - n1).max() < 1e-6
    # frames change continuously: consecutive reference vectors stay close
    step = np.linalg.norm(np.diff(F[:, :, 0], axis=0), axis=1)
    assert step.max() < 0.2
    # on the run (tangent constant, +x) the fill turns the frame at a constant rate per unit
    # length from the first arc's N (+y) to the second arc's N (+z)
    mid = slice(len(arc1) + 8, len(arc1) + 31)
    ang = np.unwrap(np.arctan2(F[mid, 2, 0], F[mid, 1, 0]))
    assert np.ptp(np.diff(ang)) < 1e-6 and abs(np.diff(ang).mean()) > 1e-3


def test_frenet_planar_inflection_sample():
    """S-shaped planar curve sampled exactly at its inflection: defined, finite, in-plane."""
    b = Bezier([[0, 0, 0], [1, 1, 0], [2, -1, 0], [3, 0, 0]])  # inflection at u = 1/2
    F = spinal.frames(b, u=np.linspace(0, 1, 101), method="frenet")
    assert np.all(np.isfinite(F)) and orthonormality_error(F) < 1e-12
    inplane = np.r_[0:50, 51:101]
    assert np.abs(F[inplane, 2, 0]).max() < 1e-12  # N stays in the plane where defined
    np.testing.assert_allclose(np.abs(F[inplane, 2, 1]), 1.0, atol=1e-12)  # B = ±z
    # the Frenet frame flips across the inflection; the undefined sample u = 1/2 is filled
    # half-way (r = ±z), so the frames stay continuous in angle
    assert F[49, 2, 1] * F[51, 2, 1] < 0
    np.testing.assert_allclose(abs(F[50, 2, 0]), 1.0, atol=1e-6)


def test_frenet_straight_line_falls_back_to_rmf():
    x = np.c_[np.linspace(0, 1, 20), np.linspace(0, 2, 20), np.zeros(20)]
    F = spinal.frames(x, method="frenet")
    assert np.abs(F - F[0]).max() < 1e-15
