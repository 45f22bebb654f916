"""The posed spine's frames of :class:`spinal.SpineBinding`: the default start of the posed
rotation-minimizing frames, and the roll the caller gives (``posed_frames``, ``posed_up``)."""

from __future__ import annotations

import numpy as np

from . import _core
from ._types import Array
from ._validate import as_float_array


def _unit_sized(a: np.ndarray) -> np.ndarray:
    """``a`` times the power of two that brings its largest absolute entry into [0.5, 1)
    (exact; ``a`` itself when it is zero)."""
    m = float(np.abs(a).max(initial=0.0))
    return np.ldexp(a, -np.frexp(m)[1]) if m > 0 and np.isfinite(m) else a


def _posed_initial(rest: np.ndarray, f0: np.ndarray, posed: np.ndarray, t1: np.ndarray
                   ) -> np.ndarray:
    """Reference vector of the posed spine's first frame (a choice of ours: Zhuo 2014 does not
    say how the posed spine's initial normal is chosen; any choice keeps the volume; this one is
    rigid-motion equivariant and symmetric): ``r1 = Q R_t0(ψ) r0`` with ``Q`` the minimal
    rotation taking the rest start tangent ``t0`` to the posed one ``t1`` and ``ψ`` the twist
    about ``t0`` (swing–twist split) of ``Qᵀ K``, ``K`` the best-fit (Kabsch) rotation of the
    rest onto the posed samples; ``ψ = 0`` when either spine is straight (the roll about it is
    then free). A rigid motion ``K`` gives ``r1 = K r0``; swapping the spines gives the
    inverse roll."""
    r0, t0 = f0[:, 0], f0[:, 2]
    q = _core.minimal_rotation(t0, t1)
    # each spine divided by a power of two near its size first (exact; the rotation does not
    # depend on it): the products of coordinates below leave float64's range beyond 1e±150
    a = _unit_sized(rest - rest.mean(0))
    b = _unit_sized(posed - posed.mean(0))
    u, sv, vt = np.linalg.svd(a.T @ b)
    sa = np.linalg.svd(a, compute_uv=False)
    sb = np.linalg.svd(b, compute_uv=False)
    psi = 0.0
    if sv[1] > 1e-9 * sv[0] and sa[1] > 1e-9 * sa[0] and sb[1] > 1e-9 * sb[0]:
        d = np.sign(np.linalg.det(vt.T @ u.T)) or 1.0
        k = vt.T @ np.diag([1.0, 1.0, d]) @ u.T
        m = q.T @ k
        # quaternion (v, w) of m, up to a common factor; its twist about t0 has angle
        # 2 atan2(v·t0, w)
        w = 1.0 + np.trace(m)
        v = np.array([m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1]])
        psi = 2 * np.arctan2(v @ t0, w)
    c, s = np.cos(psi), np.sin(psi)
    rolled = c * r0 + s * np.cross(t0, r0) + (1 - c) * (t0 @ r0) * t0
    out: np.ndarray = q @ rolled
    return out


def _rotations(f: np.ndarray, name: str) -> None:
    """Refuse frames that are not proper rotations (columns orthonormal, det +1)."""
    err = np.abs(np.swapaxes(f, -1, -2) @ f - np.eye(3)).max(axis=(-2, -1))
    bad = np.flatnonzero(~(err < 1e-6) | ~(np.linalg.det(f) > 0))
    if bad.size:
        raise ValueError(f"{name}: row {bad[0]} is not a rotation (expected orthonormal "
                         f"columns r, s, t with det +1, like spinal.frames)")


def _roll_to(frames1: np.ndarray, r0: np.ndarray, name: str) -> np.ndarray:
    """``frames1`` rolled about their tangents by the constant angle that turns the first
    reference vector onto ``r0`` projected on the first normal plane (the RMF is linear in
    its initial vector, so this is the RMF started from ``r0``)."""
    r, s_, t0 = frames1[0][:, 0], frames1[0][:, 1], frames1[0][:, 2]
    p = r0 - (r0 @ t0) * t0
    if not np.linalg.norm(p) > 1e-3 * np.linalg.norm(r0):
        raise ValueError(f"{name}: its reference vector is parallel to the posed spine's "
                         f"first tangent")
    g = np.arctan2(p @ s_, p @ r)
    c, sn = np.cos(g), np.sin(g)
    out = frames1.copy()
    rr, ss = frames1[:, :, 0], frames1[:, :, 1]
    out[:, :, 0] = c * rr + sn * ss
    out[:, :, 1] = c * ss - sn * rr
    return out


def _given_roll(frames1: np.ndarray, posed_frames: Array | None, posed_up: Array | None,
                at: np.ndarray, m: int, closed: bool) -> np.ndarray:
    """The posed frames with the roll the caller gives: ``frames1`` (the posed spine's frames,
    whose tangents are kept) with ``r`` the given reference vectors — the ``r`` columns of
    ``posed_frames`` or the ``posed_up`` vectors at the caller's ``m`` posed rows — blended
    linearly to the positions ``at`` (``k + u`` on the caller's polyline) of the samples and
    projected onto their normal planes. One ``(3, 3)`` frame instead sets the first frame:
    the RMF started from it."""
    name = "posed_frames" if posed_frames is not None else "posed_up"
    t = frames1[:, :, 2]
    if posed_frames is not None:
        f = as_float_array(posed_frames, name)
        if f.shape == (3, 3):
            _rotations(f[None], name)
            return _roll_to(frames1, f[:, 0], name)
        if closed and f.shape == (m + 1, 3, 3):  # the caller repeated the first row
            f = f[:m]
        if f.shape != (m, 3, 3):
            raise ValueError(f"{name}: expected shape (3, 3) or ({m}, 3, 3) like posed_spine's "
                             f"rows, got {f.shape}")
        _rotations(f, name)
        vecs, tg = f[:, :, 0], f[:, :, 2]
    else:
        u = as_float_array(posed_up, name)
        if closed and u.shape == (m + 1, 3):
            u = u[:m]
        if u.shape == (3,):
            u = np.broadcast_to(u, (m, 3))
        if u.shape != (m, 3):
            raise ValueError(f"{name}: expected shape (3,) or ({m}, 3) like posed_spine's rows, "
                             f"got {u.shape}")
        # directions: each row divided by its largest component first, so that lengths of
        # 1e300 or 1e-300 neither overflow nor vanish in the norm
        big = np.abs(u).max(axis=1, keepdims=True)
        bad = np.flatnonzero(~np.isfinite(u).all(axis=1) | ~(big[:, 0] > 0))
        if bad.size:
            raise ValueError(f"{name}: row {bad[0]} is not a finite non-zero vector")
        u = u / big
        vecs, tg = u / np.linalg.norm(u, axis=1, keepdims=True), None
    # the caller's rows around every sample
    k = np.floor(at).astype(np.int64)
    if closed:
        k %= m
        nxt = (k + 1) % m
        w = np.clip(at - np.floor(at), 0.0, 1.0)
    else:
        k = np.clip(k, 0, m - 2)
        nxt = k + 1
        w = np.clip(at - k, 0.0, 1.0)
    row = np.where(w < 0.5, k, nxt)
    if tg is not None:
        tb = (1 - w)[:, None] * tg[k] + w[:, None] * tg[nxt]
        cos = np.einsum("ij,ij->i", tb, t) / np.linalg.norm(tb, axis=1)
        bad = np.flatnonzero(~(cos > 0.5))
        if bad.size:
            j = bad[0]
            raise ValueError(
                f"{name}: row {row[j]}: its t column is "
                f"{np.degrees(np.arccos(np.clip(cos[j], -1, 1))):.0f}° from the posed spine's "
                f"tangent (expected the posed spine's frames, columns r, s, t like spinal.frames)")
    v = (1 - w)[:, None] * vecs[k] + w[:, None] * vecs[nxt]
    r = v - np.einsum("ij,ij->i", v, t)[:, None] * t
    nr = np.linalg.norm(r, axis=1)
    bad = np.flatnonzero(~(nr > 1e-3))
    if bad.size:
        j = bad[0]
        raise ValueError(f"{name}: row {row[j]}: the reference vector is parallel to the posed "
                         f"spine's tangent (or turns by a half turn between rows)")
    r = r / nr[:, None]
    dots = np.einsum("ij,ij->i", r[:-1], r[1:])
    if closed:
        dots = np.r_[dots, r[-1] @ r[0]]
    bad = np.flatnonzero(~(dots > -0.5))
    if bad.size:
        raise ValueError(f"{name}: the roll turns by 120° or more between posed samples "
                         f"{bad[0]} and {(bad[0] + 1) % len(r)}; give a roll that turns less "
                         f"between samples")
    out = frames1.copy()
    out[:, :, 0] = r
    out[:, :, 1] = np.cross(t, r)
    return out
