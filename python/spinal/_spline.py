"""The numerics behind :class:`spinal.curves.Spline` (the class is in ``_curves.py``).

Every kind of spline is reduced to one representation: ``m`` cubic pieces in the power basis
of the local parameter ``s = u − knots[i] ∈ [0, h_i]``,

    x(u) = c₀[i] + c₁[i] s + c₂[i] s² + c₃[i] s³,    coefficients ``c`` of shape (4, m, 3),

so evaluation (and every derivative) is one ``searchsorted`` and a Horner scheme, whatever
the kind. This module builds ``c`` for the three kinds, and the arc-length table that
:meth:`Spline.arc_length_parameters` inverts. Sources (see docs/references.md):

* de Boor, *A Practical Guide to Splines* (rev. ed., Springer 2001), Ch. IV: cubic Hermite
  pieces, Bessel (parabola) slopes, the cubic spline's tridiagonal system;
* Press, Teukolsky, Vetterling & Flannery, *Numerical Recipes* (3rd ed., 2007), §2.4
  (tridiagonal systems) and §2.7.2 (cyclic tridiagonal systems by Sherman–Morrison);
* Piegl & Tiller, *The NURBS Book* (2nd ed., Springer 1997), §2.5, Algorithm A2.2 (the
  non-vanishing B-spline basis functions on a knot span).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TypeAlias

import numpy as np

#: ``speed(piece, s)``: ``|x′|`` on the pieces at the local parameters ``s``.
Speed: TypeAlias = Callable[[np.ndarray, np.ndarray], np.ndarray]
#: :func:`arc_length_table`: intervals ``(piece, a, b)`` and the arc length ``S`` at their starts.
ArcTable: TypeAlias = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]

#: Gauss–Legendre nodes and weights on [−1, 1]; 16 nodes integrate polynomials of degree 31
#: exactly, and the speed |x′| (the square root of a quartic) to rounding on a piece where it
#: stays away from zero. Pieces where it does not are subdivided (:func:`arc_length_table`).
_GL_X, _GL_W = np.polynomial.legendre.leggauss(16)

#: Intervals integrated at once (16 nodes each: a few MB of temporary arrays).
_BLOCK = 1 << 14

#: Subdivision levels of the arc-length table (a piece is split in at most 2^40 parts).
_MAX_LEVELS = 40


# ----------------------------------------------------------------------- evaluation


def derivative_coefficients(c: np.ndarray) -> list[np.ndarray]:
    """The power-basis coefficients of the k-th derivatives, k = 0..3: ``(4 − k, m, 3)`` each.

    ``d^k/ds^k Σ_j c_j s^j = Σ_j c_{j+k} (j+k)!/j! s^j``."""
    out = []
    for k in range(4):
        f = np.array([math.perm(j + k, k) for j in range(4 - k)], dtype=float)
        out.append(np.ascontiguousarray(f[:, None, None] * c[k:]))
    return out


def horner(c: np.ndarray, piece: np.ndarray, s: np.ndarray) -> np.ndarray:
    """``Σ_j c[j, piece] s^j`` for each row: ``(len(s), 3)``."""
    out = np.take(c[-1], piece, axis=0)  # a new array (np.take: faster than c[-1][piece])
    for cj in c[-2::-1]:
        out *= s[:, None]
        out += np.take(cj, piece, axis=0)
    return out


# ------------------------------------------------------------- interpolating splines


#: Chord lengths an interpolating spline can be built from (its coefficients hold h±³).
_CHORDS = (1e-100, 1e100)


def row_norms(d: np.ndarray) -> np.ndarray:
    """Lengths of the rows of ``d`` (n, 3) without overflow or underflow in the squares
    (``hypot``), so splines of any size have finite, non-zero chords and speeds."""
    out: np.ndarray = np.hypot(np.hypot(d[:, 0], d[:, 1]), d[:, 2])
    return out


def chords(p: np.ndarray, closed: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Chord vectors ``Δ_i = p_{i+1} − p_i`` (closed: with the chord back to ``p_0``), their
    lengths ``h_i`` (the knot spacings of the chord-length parametrisation) and the divided
    differences ``δ_i = Δ_i / h_i`` (unit vectors). Raises on a chord of length 0."""
    d = np.diff(np.vstack([p, p[:1]]) if closed else p, axis=0)
    h = row_norms(d)
    zero = np.flatnonzero(~(h > 0))
    if not zero.size and not (_CHORDS[0] <= h.min() and h.max() <= _CHORDS[1]):
        # the pieces' coefficients hold h³ and 1/h³ (the chord-length parameter is a length)
        raise ValueError(f"points: chords from {h.min():.3g} to {h.max():.3g} leave the range "
                         f"1e-100 … 1e100 where the chord-length pieces stay finite; rescale "
                         f"the points (the spline is the same in any unit)")
    if zero.size:
        i = int(zero[0])
        j = (i + 1) % len(p)
        what = " (the closing chord)" if closed and j == 0 else ""
        raise ValueError(f"points: rows {i} and {j} coincide{what}; the chord-length "
                         f"parametrisation needs distinct consecutive points")
    if not np.isfinite(h.sum()):
        raise ValueError("points: the chord lengths overflow (coordinates too large)")
    return d, h, d / h[:, None]


def hermite_pieces(p: np.ndarray, m: np.ndarray, h: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Power-basis coefficients of the cubic Hermite pieces with end values ``p_i, p_{i+1}``
    and end slopes ``m_i, m_{i+1}`` on ``[0, h_i]`` (de Boor Ch. IV): with ``δ = Δ/h``,
    ``c₀ = p_i, c₁ = m_i, c₂ = (3δ − 2m_i − m_{i+1})/h, c₃ = (m_i + m_{i+1} − 2δ)/h²``.
    ``p``, ``m``: the values and slopes at the left ends of the pieces and one more row."""
    hh = h[:, None]
    m0, m1 = m[:-1], m[1:]
    return np.stack([p[:-1], m0, (3 * d - 2 * m0 - m1) / hh, (m0 + m1 - 2 * d) / hh**2])


def catmull_rom_slopes(h: np.ndarray, d: np.ndarray, closed: bool) -> np.ndarray:
    """Slopes at the knots (n rows; closed: n + 1, the last repeating the first).

    Interior (and every knot of a closed curve): the derivative at ``t_i`` of the parabola
    through ``(t_{i−1}, p_{i−1}), (t_i, p_i), (t_{i+1}, p_{i+1})``,

        m_i = (h_i δ_{i−1} + h_{i−1} δ_i) / (h_{i−1} + h_i),

    the weighted mean of the neighbouring divided differences (Bessel's slope, de Boor
    Ch. IV). Open ends: the slope at the end of the parabola through the three end points,
    ``m_0 = ((2h_0 + h_1) δ_0 − h_0 δ_1)/(h_0 + h_1)`` (mirrored at the last point); two
    points: the chord."""
    if closed:
        hp, dp = np.roll(h, 1), np.roll(d, 1, axis=0)  # h_{i−1}, δ_{i−1} round the loop
        m = (h[:, None] * dp + hp[:, None] * d) / (hp + h)[:, None]
        return np.vstack([m, m[:1]])
    if len(h) == 1:
        return np.vstack([d, d])
    hp, hn = h[:-1, None], h[1:, None]
    inner = (hn * d[:-1] + hp * d[1:]) / (hp + hn)
    first = ((2 * h[0] + h[1]) * d[0] - h[0] * d[1]) / (h[0] + h[1])
    last = ((2 * h[-1] + h[-2]) * d[-1] - h[-1] * d[-2]) / (h[-1] + h[-2])
    return np.vstack([first, inner, last])


def natural_pieces(p: np.ndarray, h: np.ndarray, d: np.ndarray, closed: bool) -> np.ndarray:
    """Power-basis coefficients of the C² cubic spline through ``p`` at the knots.

    Unknowns: the second derivatives ``M_i`` at the knots. Continuity of x′ at the interior
    knots gives the symmetric, strictly diagonally dominant system (de Boor Ch. IV)

        h_{i−1} M_{i−1} + 2 (h_{i−1} + h_i) M_i + h_i M_{i+1} = 6 (δ_i − δ_{i−1}),

    with ``M_0 = M_{n−1} = 0`` (natural ends), or for all ``i`` modulo ``n`` (periodic: a
    cyclic tridiagonal system). Then on piece ``i``: ``c₀ = p_i``,
    ``c₁ = δ_i − h_i (2M_i + M_{i+1})/6``, ``c₂ = M_i/2``, ``c₃ = (M_{i+1} − M_i)/(6h_i)``."""
    n_pieces = len(h)
    rhs = 6 * np.diff(np.vstack([d[-1:], d]) if closed else d, axis=0)
    M = np.zeros((n_pieces + 1, 3))
    if closed:
        hp = np.roll(h, 1)  # h_{i−1}; row i: sub h_{i−1}, diagonal 2(h_{i−1} + h_i), super h_i
        M[:-1] = cyclic_tridiagonal(hp, 2 * (hp + h), h, rhs)
        M[-1] = M[0]
    elif n_pieces > 1:
        M[1:-1] = tridiagonal(h[:-1], 2 * (h[:-1] + h[1:]), h[1:], rhs)
    hh = h[:, None]
    return np.stack([p[:n_pieces], d - hh * (2 * M[:-1] + M[1:]) / 6, M[:-1] / 2,
                     (M[1:] - M[:-1]) / (6 * hh)])


def tridiagonal(a: np.ndarray, b: np.ndarray, c: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Solve ``a_i x_{i−1} + b_i x_i + c_i x_{i+1} = r_i`` (``a_0``, ``c_{n−1}`` unused) by
    Gaussian elimination without pivoting (the Thomas algorithm, Numerical Recipes §2.4;
    stable for the diagonally dominant systems here). ``r``: ``(n, k)``, k right-hand sides.

    Elimination turns row i into ``x_i + c′_i x_{i+1} = r′_i`` with ``β_i = b_i − a_i c′_{i−1}``,
    ``c′_i = c_i/β_i``, ``r′_i = (r_i − a_i r′_{i−1})/β_i``; back substitution
    ``x_i = r′_i − c′_i x_{i+1}``. The recurrences run on Python floats (much faster than
    NumPy scalars), one column at a time."""
    a, b, c = (np.asarray(v, dtype=float).tolist() for v in (a, b, c))
    n = len(b)
    beta, cp = [0.0] * n, [0.0] * n
    beta[0] = b[0]
    for i in range(1, n):
        cp[i - 1] = c[i - 1] / beta[i - 1]
        beta[i] = b[i] - a[i] * cp[i - 1]
    out = np.empty((n, r.shape[1]))
    for col in range(r.shape[1]):
        x = r[:, col].tolist()
        x[0] /= beta[0]
        for i in range(1, n):  # forward elimination
            x[i] = (x[i] - a[i] * x[i - 1]) / beta[i]
        for i in range(n - 2, -1, -1):  # back substitution
            x[i] -= cp[i] * x[i + 1]
        out[:, col] = x
    return out


def cyclic_tridiagonal(a: np.ndarray, b: np.ndarray, c: np.ndarray, r: np.ndarray
                       ) -> np.ndarray:
    """Solve the cyclic system of :func:`tridiagonal` with corners ``A[0, n−1] = a_0`` and
    ``A[n−1, 0] = c_{n−1}`` (n ≥ 3) by Sherman–Morrison (Numerical Recipes §2.7.2):
    ``A = B + u vᵀ`` with ``u = (γ, 0, …, 0, c_{n−1})``, ``v = (1, 0, …, 0, a_0/γ)``,
    ``γ = −b_0``, and ``B`` tridiagonal with ``b_0 − γ`` and ``b_{n−1} − a_0 c_{n−1}/γ`` on the
    diagonal; then ``x = y − (v·y)/(1 + v·z) z`` with ``B y = r``, ``B z = u``."""
    n = len(b)
    alpha, beta, gamma = c[-1], a[0], -b[0]
    bb = b.astype(float).copy()
    bb[0] -= gamma
    bb[-1] -= alpha * beta / gamma
    u = np.zeros(n)
    u[0], u[-1] = gamma, alpha
    yz = tridiagonal(a, bb, c, np.column_stack([r, u]))  # both solves in one sweep
    y, z = yz[:, :-1], yz[:, -1]
    vy = y[0] + beta / gamma * y[-1]
    vz = z[0] + beta / gamma * z[-1]
    return y - np.outer(z, vy / (1 + vz))


# ----------------------------------------------------------------------- B-splines


def bspline_pieces(t: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The breakpoints ``t_3 … t_N`` and power-basis coefficients of the cubic B-spline
    ``Σ_k q_k N_{k,3}(u)`` with knot vector ``t`` (``N + 4`` knots, N control points, every
    span of ``[t_3, t_N]`` non-empty).

    On the span ``[t_j, t_{j+1})`` only ``N_{j−3,3} … N_{j,3}`` are non-zero. They come from
    the Cox–de Boor recurrence in the triangular form of Piegl & Tiller's Algorithm A2.2,
    run on polynomials in ``s = u − t_j`` instead of numbers, for all spans at once:
    ``left_r = u − t_{j+1−r} = s + (t_j − t_{j+1−r})``, ``right_r = t_{j+r} − u``, and each
    step divides by the constant ``right_{k+1} + left_{r−k} = t_{j+k+1} − t_{j+1−r+k}`` > 0."""
    t = np.asarray(t, dtype=float)
    j = np.arange(3, len(q))  # one span per piece
    tj = t[j]

    def times_linear(poly: np.ndarray, const: np.ndarray, slope: float) -> np.ndarray:  # poly · (const + slope s), degree stays ≤ 3
        out = const[:, None] * poly
        out[:, 1:] += slope * poly[:, :-1]
        res: np.ndarray = out
        return res

    basis = [np.zeros((len(j), 4)) for _ in range(4)]
    basis[0][:, 0] = 1.0
    for r in range(1, 4):
        saved = np.zeros((len(j), 4))
        for k in range(r):
            temp = basis[k] / (t[j + k + 1] - t[j + 1 - r + k])[:, None]
            basis[k] = saved + times_linear(temp, t[j + k + 1] - tj, -1.0)
            saved = times_linear(temp, tj - t[j + 1 - r + k], 1.0)
        basis[r] = saved
    # c[power, piece] = Σ_k N_{j−3+k}[power] q_{j−3+k}
    c = sum(basis[k].T[:, :, None] * q[j - 3 + k][None] for k in range(4))
    return t[3:len(q) + 1].copy(), c


def clamped_knots(n: int) -> np.ndarray:
    """``[0, 0, 0, 0, 1, …, n−4, n−3, n−3, n−3, n−3]`` (n + 4 knots for n control points)."""
    return np.concatenate([np.zeros(3), np.arange(n - 2.0), np.full(3, n - 3.0)])


def periodic_bspline(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Breakpoints ``0 … n`` and coefficients of the closed uniform cubic B-spline: the
    control polygon wrapped as ``p_{n−1}, p_0, …, p_{n−1}, p_0, p_1`` on the knots
    ``−3, −2, …, n + 3``, so piece ``i`` (``u ∈ [i, i+1]``) is shaped by ``p_{i−1} … p_{i+2}``
    and ``x(i) = (p_{i−1} + 4 p_i + p_{i+1})/6`` (indices modulo n)."""
    n = len(p)
    q = np.vstack([p[-1:], p, p[:2]])
    return bspline_pieces(np.arange(-3.0, n + 4), q)


# --------------------------------------------------------------------- arc length


def _integrals(speed: Speed, piece: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``∫_a^b speed(piece, s) ds`` by 16-point Gauss–Legendre, for arrays of intervals (in
    blocks, to bound the temporary arrays of 16 nodes per interval)."""
    out = np.empty(len(a))
    for k in range(0, len(a), _BLOCK):
        blk = slice(k, k + _BLOCK)
        half = 0.5 * (b[blk] - a[blk])
        s = (0.5 * (a[blk] + b[blk]))[:, None] + half[:, None] * _GL_X
        v = speed(np.repeat(piece[blk], len(_GL_X)), s.ravel()).reshape(s.shape)
        out[blk] = half * (v @ _GL_W)
    return out


def arc_length_table(speed: Speed, h: np.ndarray) -> ArcTable:
    """Intervals ``(piece, a, b)`` of local parameters covering all pieces in order, and the
    arc length ``S`` at their starts (one more entry: the total length).

    Adaptive: an interval is kept when its 16-point Gauss–Legendre integral agrees with the
    sum over its two halves to 1e-13 relative (1e-15 of the whole length absolute), else it
    is halved and tested again; the kept value is the halves' sum (the better one). The
    speed is analytic on a piece except near its zeros (cusps), where the halving
    concentrates."""
    piece, a, b = np.arange(len(h)), np.zeros(len(h)), np.asarray(h, dtype=float)
    kept: list[tuple[np.ndarray, ...]] = []
    scale = None
    for level in range(_MAX_LEVELS + 1):
        mid = 0.5 * (a + b)
        whole = _integrals(speed, piece, a, b)
        halves = _integrals(speed, piece, a, mid) + _integrals(speed, piece, mid, b)
        if scale is None:
            scale = float(halves.sum())
        ok = np.abs(whole - halves) <= 1e-13 * halves + 1e-15 * scale
        # an integral that is not finite cannot be refined by halving
        ok |= ~(np.isfinite(whole) & np.isfinite(halves))
        if level == _MAX_LEVELS:
            ok[:] = True
        kept.append((piece[ok], a[ok], b[ok], halves[ok]))
        bad = ~ok
        if not bad.any():
            break
        piece = np.repeat(piece[bad], 2)
        a, b = np.column_stack([a[bad], mid[bad]]).ravel(), np.column_stack(
            [mid[bad], b[bad]]).ravel()
    piece, a, b, length = (np.concatenate(x) for x in zip(*kept))
    order = np.lexsort((a, piece))
    piece, a, b, length = piece[order], a[order], b[order], length[order]
    S = np.concatenate([[0.0], np.cumsum(length)])
    return piece, a, b, S


def invert_arc_length(speed: Speed, table: ArcTable, targets: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray]:
    """The pieces and local parameters ``s`` where the arc length reaches ``targets``.

    In the table's interval ``[a, b]`` holding the target, solve
    ``F(s) = S_a + ∫_a^s |x′| − target = 0`` (F increases, ``F′ = |x′|``) by Newton's method
    from the linear guess, each step kept inside the bracket that the signs of F have
    narrowed so far and replaced by bisection where it leaves it (or where ``|x′| = 0``)."""
    piece_t, a_t, b_t, S = table
    j = np.clip(np.searchsorted(S, targets, side="right") - 1, 0, len(a_t) - 1)
    piece, lo, hi = piece_t[j], a_t[j].copy(), b_t[j].copy()
    a, r, span = a_t[j], targets - S[j], S[j + 1] - S[j]
    s = lo + (hi - lo) * np.clip(np.divide(r, span, out=np.zeros_like(r), where=span > 0),
                                 0, 1)
    tol = 1e-14 * np.maximum(span, 1e-300)  # on F: a few roundings of the sum of 16 terms
    width = 1e-15 * (hi - lo)  # a bracket this narrow has converged too (F′ = |x′| ≈ 0)
    todo = np.arange(len(targets))
    for _ in range(200):  # Newton converges in a few steps; bisection alone in ~60
        p, x = piece[todo], s[todo]
        F = _integrals(speed, p, a[todo], x) - r[todo]
        done = (np.abs(F) <= tol[todo]) | (hi[todo] - lo[todo] <= width[todo])
        lo[todo] = np.where(F < 0, x, lo[todo])
        hi[todo] = np.where(F > 0, x, hi[todo])
        with np.errstate(divide="ignore", invalid="ignore"):
            step = x - F / speed(p, x)
        inside = (step > lo[todo]) & (step < hi[todo])
        s[todo] = np.where(done, x, np.where(inside, step, 0.5 * (lo[todo] + hi[todo])))
        todo = todo[~done]
        if not todo.size:
            break
    return piece, s
