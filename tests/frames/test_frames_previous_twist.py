"""``spinal.frames(previous=, previous_twist=True)``: the frames follow the previous frames'
twist profile (their ``r`` columns as a guide), not only their start.

Independent reference: on a curve that does not move, the previous frames are an exact RMF
rolled by a known smooth function; they must come back up to the guide's smoothing bias,
which shrinks like ``1/guide_weight``.
"""

import numpy as np
import pytest

import spinal


def helix(n=200):
    u = np.linspace(0, 3 * np.pi, n)
    return np.c_[np.cos(u), np.sin(u), 0.3 * u]


def rolled(F, theta):
    c, s = np.cos(theta)[:, None], np.sin(theta)[:, None]
    out = F.copy()
    out[:, :, 0] = c * F[:, :, 0] + s * F[:, :, 1]
    out[:, :, 1] = c * F[:, :, 1] - s * F[:, :, 0]
    return out


def rotation_angle(a, b):
    tr = np.einsum("nij,nij->n", a, b)  # trace(a bᵀ)
    return np.arccos(np.clip((tr - 1) / 2, -1, 1))


def test_a_still_curve_keeps_the_previous_twist():
    P = helix()
    n = len(P)
    F = spinal.frames(P)
    s = np.arange(n) / (n - 1)
    theta = 1.0 + 1.2 * np.sin(np.pi * s) ** 2  # a start turn and a twist, flat at the ends
    prev = rolled(F, theta)
    curv = np.abs(np.diff(theta, 2)).max()  # φ″ per sample²
    errs = []
    for w in (1.0, 10.0, 100.0):
        G = spinal.frames(P, previous=prev, previous_twist=True, guide_weight=w)
        # the tangents are the curve's
        assert np.abs(G[:, :, 2] - F[:, :, 2]).max() < 1e-15
        errs.append(rotation_angle(G, prev).max())
        assert errs[-1] < 1.05 * curv / w, (w, errs[-1], curv)  # bias ≈ φ″/W
    assert errs[0] / errs[1] > 5 and errs[1] / errs[2] > 5, errs
    # without it: one turn for all, the twist profile is lost
    only_start = spinal.frames(P, previous=prev)
    assert rotation_angle(only_start, prev).max() > 0.5


def test_per_curve_in_a_bundle_and_closed():
    P = helix()
    F = spinal.frames(P)
    s = np.arange(len(P)) / (len(P) - 1)
    prev = rolled(F, 0.7 * np.sin(np.pi * s) ** 2)
    both = np.concatenate([P, P[::-1]])
    Fb = spinal.frames(both, lengths=[len(P), len(P)])
    prev_b = np.concatenate([prev, rolled(Fb[len(P):], -0.4 * np.sin(np.pi * s) ** 2)])
    G = spinal.frames(both, lengths=[len(P), len(P)], previous=prev_b, previous_twist=True,
                      guide_weight=100.0)
    assert rotation_angle(G, prev_b).max() < 1e-3
    u = np.linspace(0, 2 * np.pi, 120, endpoint=False)
    loop = np.c_[np.cos(u), np.sin(u), 0.3 * np.sin(2 * u)]
    C = spinal.frames(loop, closed=True)
    prev = rolled(C, 0.5 + 0.3 * np.sin(u))
    G = spinal.frames(loop, closed=True, previous=prev, previous_twist=True, guide_weight=100.0)
    assert rotation_angle(G, prev).max() < 1e-3


def test_bad_previous_twist_is_named():
    P = helix(50)
    F = spinal.frames(P)
    with pytest.raises(TypeError, match="^previous_twist: needs previous"):
        spinal.frames(P, previous_twist=True)
    with pytest.raises(TypeError, match="^previous_twist:"):
        spinal.frames(P, previous=F, previous_twist="yes")
    with pytest.raises(ValueError, match="^previous_weight: must be a positive"):
        spinal.frames(P, previous=F, guide=[0, 0, 1], previous_weight=-1.0)
    with pytest.raises(ValueError, match="^previous: cannot be combined with initial"):
        spinal.frames(P, previous=F, previous_twist=True, initial=[1, 0, 0])
    with pytest.raises(ValueError, match=r"^previous: expected shape \(50, 3, 3\)"):
        spinal.frames(P, previous=F[:-1], previous_twist=True)
    bad = F.copy()
    bad[7] *= 2
    with pytest.raises(ValueError, match="^previous: row 7 is not a rotation matrix"):
        spinal.frames(P, previous=bad, previous_twist=True)
    with pytest.raises(ValueError, match="^previous: is not used by method='frenet'"):
        spinal.frames(P, previous=F, previous_twist=True, method="frenet")
