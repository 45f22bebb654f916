"""Bernstein-form pieces of :mod:`spinal.ph`: products and degree elevation of polynomial
rows, the numerators of the rational rotation-minimizing frame (Farouki's Euler–Rodrigues
frame), the patches of a rational sweep, and the finiteness check of the inputs."""

from __future__ import annotations

from math import comb
from typing import Any

import numpy as np

from ._types import Array
from ._validate import as_float_array


def _finite(a: np.ndarray, name: str) -> np.ndarray:
    """Finite values, for the inputs of Python-side computations (the core checks its own)."""
    if not np.all(np.isfinite(a)):
        bad = np.argwhere(~np.isfinite(a))[0]
        raise ValueError(f"{name}: contains non-finite values (at index {tuple(bad.tolist())})")
    return a


def _bmul(f: np.ndarray, g: np.ndarray) -> np.ndarray:
    """Product of Bernstein polynomials ``(m, p+1, ...)`` and ``(m, q+1, ...)``."""
    p, q = f.shape[1] - 1, g.shape[1] - 1
    while f.ndim < g.ndim:
        f = f[..., None]
    while g.ndim < f.ndim:
        g = g[..., None]
    shape = np.broadcast_shapes(f[:, :1].shape, g[:, :1].shape)
    out = np.zeros((shape[0], p + q + 1) + shape[2:])
    for i in range(p + 1):
        for j in range(q + 1):
            out[:, i + j] += comb(p, i) * comb(q, j) / comb(p + q, i + j) * f[:, i] * g[:, j]
    return out


def _elevate(f: np.ndarray, to: int) -> np.ndarray:
    """Degree elevation along axis 1 up to degree ``to``."""
    while f.shape[1] - 1 < to:
        m = f.shape[1]  # new degree
        g = np.zeros((f.shape[0], m + 1) + f.shape[2:])
        for i in range(m + 1):
            a = i / m
            if i > 0:
                g[:, i] += a * f[:, i - 1]
            if i < m:
                g[:, i] += (1 - a) * f[:, i]
        f = g
    return f


def _beval(f: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Evaluate Bernstein coefficients ``(p+1, ...)`` at ``v`` (n,) -> ``(n, ...)``."""
    p = f.shape[0] - 1
    B = np.stack([comb(p, i) * v**i * (1 - v) ** (p - i) for i in range(p + 1)], axis=1)
    return np.tensordot(B, f, axes=(1, 0))


def _erf_col(k: int, p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Symmetric bilinear form of column ``k`` of ``R(A)|A|²`` (scalar-first ``(m, 4)``):
    ``col(A, A)`` is ``A i A*``, ``A j A*``, ``A k A*`` for k = 0, 1, 2."""
    w1, x1, y1, z1 = p.T
    w2, x2, y2, z2 = q.T
    if k == 0:
        c = (w1 * w2 + x1 * x2 - y1 * y2 - z1 * z2, x1 * y2 + y1 * x2 + w1 * z2 + z1 * w2,
             x1 * z2 + z1 * x2 - w1 * y2 - y1 * w2)
    elif k == 1:
        c = (x1 * y2 + y1 * x2 - w1 * z2 - z1 * w2, w1 * w2 - x1 * x2 + y1 * y2 - z1 * z2,
             y1 * z2 + z1 * y2 + w1 * x2 + x1 * w2)
    else:
        c = (x1 * z2 + z1 * x2 + w1 * y2 + y1 * w2, y1 * z2 + z1 * y2 - w1 * x2 - x1 * w2,
             w1 * w2 - x1 * x2 - y1 * y2 + z1 * z2)
    return np.stack(c, axis=1)


def _rational_numerators(fit: dict[str, Any]) -> dict[str, np.ndarray]:
    """Bernstein numerators of the rational RMF of bent cubics from :func:`angle_fit` data
    (see :meth:`PHSpline.rational_frames`): ``f2, f3`` (m, 7, 3), ``weight`` (m, 7),
    ``tangent`` (m, 3, 3) and ``speed`` (m, 3)."""
    A0, A1 = fit["preimage"][:, 0], fit["preimage"][:, 1]
    cols = [np.stack([_erf_col(k, A0, A0), _erf_col(k, A0, A1), _erf_col(k, A1, A1)], 1)
            for k in range(3)]                      # each (m, 3 coefficients, 3)
    speed = np.stack([(A0 * A0).sum(1), (A0 * A1).sum(1), (A1 * A1).sum(1)], axis=1)
    psi = fit["erf_angle"] + fit["phi"]
    cp_, sp_ = np.cos(psi)[:, None, None], np.sin(psi)[:, None, None]
    e2 = cp_ * cols[1] + sp_ * cols[2]
    e3 = cp_ * cols[2] - sp_ * cols[1]
    G = fit["sg"][:, None] * fit["gamma"]
    B = fit["beta"]
    GB2 = 2 * _bmul(G, B)
    BG = _bmul(B, B) - _bmul(G, G)
    return {"f2": _bmul(GB2, e3) + _bmul(BG, e2), "f3": _bmul(BG, e3) - _bmul(GB2, e2),
            "weight": _bmul(speed, _bmul(B, B) + _bmul(G, G)), "tangent": cols[0],
            "speed": speed}


def _straighten(rf: dict[str, np.ndarray], st: np.ndarray, cp: np.ndarray, r: np.ndarray) -> None:
    """Overwrite the rows ``st`` (a boolean mask) of ``rf`` — the straight cubics ``cp``
    (k, 4, 3) — with constant numerators: ``r`` (k, 3) the reference vectors, weight 1, and
    the polynomial tangent ``3d`` with its speed."""
    d = np.diff(cp, axis=1)
    t = d[:, 0] / np.linalg.norm(d[:, 0], axis=1)[:, None]
    rf["f2"][st] = r[:, None, :]
    rf["f3"][st] = np.cross(t, r)[:, None, :]
    rf["weight"][st] = 1.0
    L = np.linalg.norm(d, axis=2)
    rf["tangent"][st] = 3 * d
    rf["speed"][st] = 3 * np.stack([L[:, 0], np.einsum("ij,ij->i", d[:, 0], d[:, 1]) / L[:, 0],
                                    L[:, 2]], axis=1)


def _section(section_ctrl: Array, section_weights: Array | None) -> tuple[np.ndarray, np.ndarray]:
    """Cross-section control points ``(m + 1, 2)`` and their positive weights."""
    c = _finite(as_float_array(section_ctrl, "section_ctrl"), "section_ctrl")
    if c.ndim != 2 or c.shape[1] != 2 or c.shape[0] < 1:
        raise ValueError(f"section_ctrl: expected shape (m + 1, 2), got {c.shape}")
    if section_weights is None:
        return c, np.ones(c.shape[0])
    wj = _finite(as_float_array(section_weights, "section_weights"), "section_weights")
    if wj.shape != (c.shape[0],):
        raise ValueError(f"section_weights: expected shape ({c.shape[0]},), got "
                         f"{wj.shape}")
    if not np.all(wj > 0):
        raise ValueError("section_weights: must be positive")
    return c, wj


def _sweep_patches(cp: np.ndarray, rf: dict[str, np.ndarray], c: np.ndarray, wj: np.ndarray) -> np.ndarray:
    """Homogeneous control points ``(segments, 10, m + 1, 4)`` of the rational sweep of the
    section ``(c, wj)`` along cubics ``cp`` with the rational frame ``rf``."""
    om = _elevate(rf["weight"], 9)                    # (m, 10)
    xom = _bmul(cp, rf["weight"])                     # (m, 10, 3)
    F2 = _elevate(rf["f2"], 9)
    F3 = _elevate(rf["f3"], 9)
    C0, C2, C3 = wj, wj * c[:, 0], wj * c[:, 1]
    num = (xom[:, :, None, :] * C0[None, None, :, None]
           + F2[:, :, None, :] * C2[None, None, :, None]
           + F3[:, :, None, :] * C3[None, None, :, None])
    wt = om[:, :, None] * C0[None, None, :]
    return np.concatenate([num, wt[..., None]], axis=3)
