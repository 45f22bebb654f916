"""The pieces of :func:`spinal.ph.fit`: the PH cubics of many intervals at once, their
deviation from the curve, the starting knots (inflections, turning tangents) and the knots
the caller fixes."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from . import _core
from ._ph_bezier import _finite
from ._types import Array
from ._validate import as_float_array, as_int

if TYPE_CHECKING:
    from ._curves import Curve


_REASONS = {
    1: "no PH cubic: the end tangents are parallel but the chord is not along them",
    2: "no PH cubic: the end tangents are antiparallel and the chord is along them",
    3: "no PH cubic interpolates the data (an inflection or S-shape inside the interval)",
    4: "no PH cubic interpolates the data (only reversed polygons: an inflection or "
       "S-shape inside the interval)",
}


def _bez(cp: np.ndarray, v: np.ndarray, k: int = 0) -> np.ndarray:
    """Points (k = 0) or derivatives of cubics ``cp (q, 4, 3)`` at ``v (q, r)`` -> (q, r, 3)."""
    v = v[..., None]
    u = 1 - v
    b0, b1, b2, b3 = (cp[:, None, i] for i in range(4))
    if k == 0:
        out: np.ndarray = u**3 * b0 + 3 * u**2 * v * b1 + 3 * u * v**2 * b2 + v**3 * b3
        return out
    if k == 1:
        out = 3 * (u**2 * (b1 - b0) + 2 * u * v * (b2 - b1) + v**2 * (b3 - b2))
        return out
    out = 6 * (u * (b2 - 2 * b1 + b0) + v * (b3 - 2 * b2 + b1))
    return out


def _hermite_batch(p0: np.ndarray, t0: np.ndarray, p1: np.ndarray, t1: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Best candidate per row (q, 4, 3) and reason codes (0 = solved)."""
    try:
        cand, counts, codes = _core.ph_hermite(
            np.ascontiguousarray(p0), np.ascontiguousarray(t0), np.ascontiguousarray(p1),
            np.ascontiguousarray(t1), True, True)
    except ValueError as exc:  # a zero or non-finite tangent, a repeated point
        raise ValueError(f"curve: bad Hermite data at an interval end (rows are intervals): "
                         f"{exc}") from None
    return cand.reshape(-1, 2, 4, 3)[:, 0], counts, codes


def _dev_curve(curve: Curve, cp: np.ndarray, ta: np.ndarray, tb: np.ndarray, lo: float,
               hi: float) -> np.ndarray:
    """Max distance from 41 points of each cubic to the curve arc over [ta, tb] (per row),
    in blocks of 1024 rows (the scan needs 64 kB per row)."""
    if cp.shape[0] > 1024:
        return np.concatenate([_dev_curve(curve, cp[i:i + 1024], ta[i:i + 1024],
                                          tb[i:i + 1024], lo, hi)
                               for i in range(0, cp.shape[0], 1024)])
    q = cp.shape[0]
    v = np.broadcast_to(np.linspace(0, 1, 41), (q, 41))
    X = _bez(cp, v)
    h = tb - ta
    a = np.maximum(ta - 0.1 * h, lo)
    b = np.minimum(tb + 0.1 * h, hi)
    # coarse scan of the enlarged interval, then Newton on (p(u) − X)·p′(u) = 0
    scan = a[:, None] + (b - a)[:, None] * np.linspace(0, 1, 65)
    P = curve.point(scan.ravel()).reshape(q, 65, 3)
    d2 = ((X[:, :, None, :] - P[:, None, :, :]) ** 2).sum(-1)
    u = np.take_along_axis(scan, d2.argmin(axis=2), axis=1)
    for _ in range(12):
        flat = u.ravel()
        p, d1, dd = (f(flat).reshape(q, 41, 3) for f in (curve.point, curve.d1, curve.d2))
        e = p - X
        g = (e * d1).sum(-1)
        gp = (d1 * d1).sum(-1) + (e * dd).sum(-1)
        step = np.where(gp > 0, g / np.where(gp > 0, gp, 1.0), 0.0)
        u = np.clip(u - step, a[:, None], b[:, None])
    dist = np.linalg.norm(curve.point(u.ravel()).reshape(q, 41, 3) - X, axis=-1)
    out: np.ndarray = dist.max(axis=1)
    return out


def _dev_rows(cp: np.ndarray, pts: np.ndarray, ia: np.ndarray, ib: np.ndarray) -> np.ndarray:
    """Max distance from the rows ia..ib of ``pts`` to each cubic (Newton on v), in blocks
    of 8192 rows (every row is projected on its own, so the blocks give the same bits; each
    NumPy step stays short enough for Ctrl-C to be handled between them)."""
    out = np.zeros(cp.shape[0])
    vs = np.linspace(0, 1, 33)
    for j in range(cp.shape[0]):
        c = cp[j: j + 1]
        S = _bez(c, vs[None])[0]
        for k in range(ia[j], ib[j] + 1, 8192):
            X = pts[k: min(k + 8192, ib[j] + 1)][None]
            v = vs[((X[0, :, None, :] - S[None]) ** 2).sum(-1).argmin(axis=1)][None]
            for _ in range(12):
                e = _bez(c, v) - X
                d1, dd = _bez(c, v, 1), _bez(c, v, 2)
                g = (e * d1).sum(-1)
                gp = (d1 * d1).sum(-1) + (e * dd).sum(-1)
                v = np.clip(v - np.where(gp > 0, g / np.where(gp > 0, gp, 1.0), 0.0), 0, 1)
            out[j] = np.maximum(out[j], np.linalg.norm(_bez(c, v) - X, axis=-1).max())
    return out


def _inflections(curve: Curve, lo: float, hi: float, n: int, diag: float) -> list[float]:
    """Parameters where κ has a local minimum with κ·diag < 1e-6 (golden-section refined)."""
    u = np.linspace(lo, hi, n)
    k = curve.curvature(u)
    out: list[float] = []
    g = (np.sqrt(5) - 1) / 2
    for i in np.flatnonzero((k[1:-1] <= k[:-2]) & (k[1:-1] <= k[2:])) + 1:
        a, b = u[i - 1], u[i + 1]
        while b - a > 1e-12 * (hi - lo):
            x1, x2 = b - g * (b - a), a + g * (b - a)
            k1, k2 = curve.curvature(np.array([x1, x2]))
            if k1 <= k2:
                b = x2
            else:
                a = x1
        m = (a + b) / 2
        if curve.curvature(np.array([m]))[0] * diag < 1e-6:
            if out and m - out[-1] <= 1e-6 * (hi - lo):  # two scan minima, one inflection
                out[-1] = (out[-1] + m) / 2
            else:
                out.append(float(m))
    return out


def _initial_knots(shape: Curve | None, pts: np.ndarray | None,
                   data: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]], lo: float,
                   hi: float, diag: float) -> np.ndarray:
    """Starting knots of the adaptive fit: uniform (4 intervals of a curve, every ⌈n/8⌉-th
    row of samples), the inflections (κ minima with κ·diag < 1e-6, or rows where the
    discrete binormal flips), then intervals halved until the tangent turns by less than
    π/2 on each (8-point scan)."""
    analytic = shape is not None
    if shape is not None:
        h_min = 1e-6 * (hi - lo)
        infl = [x for x in _inflections(shape, lo, hi, 256, diag)
                if lo + h_min < x < hi - h_min]
        # uniform knots give way to nearby inflections (no sliver intervals)
        start = {x for x in np.linspace(lo, hi, 5).tolist()
                 if x in (lo, hi) or all(abs(x - y) > h_min for y in infl)}
        start.update(infl)
    else:
        assert pts is not None  # samples when not analytic
        n = pts.shape[0]
        start = set(np.arange(0, n - 1, max(1, -(-n // 8))).tolist()) | {float(n - 1)}
        d = np.diff(pts, axis=0)
        bn = np.cross(d[:-1], d[1:])
        bl = np.linalg.norm(bn, axis=1)
        ok = bl > 1e-12 * np.linalg.norm(d[:-1], axis=1) * np.linalg.norm(d[1:], axis=1)
        bn = bn / np.where(ok, bl, 1.0)[:, None]
        for j in range(len(bn) - 1):
            if ok[j] and ok[j + 1] and bn[j] @ bn[j + 1] < 0:  # rows j+1 and j+2
                start.add(float(j + 1 if bl[j] <= bl[j + 1] else j + 2))
        h_min = 1.0
    k = np.array(sorted(start))
    for _ in range(64):
        sub = k[:-1, None] + (k[1:] - k[:-1])[:, None] * np.linspace(0, 1, 9)
        if not analytic:
            sub = np.round(sub)
        t0 = data(k[:-1])[1]
        ts = data(sub.ravel())[1].reshape(sub.shape[0], 9, 3)
        turn = (ts * t0[:, None]).sum(-1).min(axis=1) <= 0
        split = turn & (np.diff(k) > h_min)
        if not split.any():
            break
        mid = (k[:-1] + k[1:])[split] / 2
        k = np.union1d(k, np.floor(mid) if not analytic else mid)
    return k


#: The largest ``segments`` of :func:`fit` (the knots, the Hermite data and the cubics are
#: held at once; 10**7 intervals exhausted the memory).
_MAX_FIT_SEGMENTS = 100_000


def _fixed_knots(segments: int | None, knots: Array | None, analytic: bool, lo: float,
                 hi: float) -> tuple[np.ndarray, str]:
    """The knots of a fit with ``segments`` uniform intervals or explicit ``knots``, and the
    name of the argument that set them."""
    if segments is not None:
        N = as_int(segments, "segments", minimum=1)
        if N > _MAX_FIT_SEGMENTS:  # the deviation needs (N, 41, 65, 3) temporaries
            raise ValueError(f"segments: must be <= {_MAX_FIT_SEGMENTS}, got {N}")
        k = np.linspace(lo, hi, N + 1)
        if not analytic:
            k = np.unique(np.round(k))
            if k.size != N + 1:
                raise ValueError(f"segments: {N} intervals need at least {N + 1} samples")
        return k, "segments"
    k = _finite(as_float_array(knots, "knots"), "knots")
    if k.ndim != 1 or k.size < 2 or not np.all(np.diff(k) > 0):
        raise ValueError("knots: expected a strictly increasing 1-D array of >= 2 values")
    if k[0] < lo or k[-1] > hi:
        raise ValueError(f"knots: must lie within [{lo:g}, {hi:g}]")
    if not analytic and not np.all(k == np.round(k)):
        raise ValueError("knots: sample knots must be integer rows")
    return k, "knots"
