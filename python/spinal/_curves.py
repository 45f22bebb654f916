"""The implementation of :mod:`spinal.curves` (see its documentation); the public names are
re-exported there."""

from __future__ import annotations

import math
from typing import Literal

import numpy as np

from ._spline import (
    ArcTable,
    arc_length_table,
    bspline_pieces,
    catmull_rom_slopes,
    chords,
    clamped_knots,
    derivative_coefficients,
    hermite_pieces,
    horner,
    invert_arc_length,
    natural_pieces,
    periodic_bspline,
    row_norms,
)
from ._types import Array, Float64Array, Param, SplineKind
from ._validate import (
    MAX_SAMPLES,
    as_bool,
    as_choice,
    as_finite,
    as_float_array,
    as_int,
    as_positive,
)

#: The largest winding number of a :class:`TorusKnot` (its third derivative grows as ``q³``).
_MAX_WINDINGS = 1_000_000

#: The kinds of :class:`Spline`.
_SPLINE_KINDS: tuple[SplineKind, ...] = ("catmull_rom", "natural_cubic", "bspline")


def _u(u: Param) -> np.ndarray:
    arr = as_float_array(u, "u")
    if arr.ndim > 1:
        raise ValueError(f"u: expected a scalar or a 1-D array, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError("u: contains non-finite values")
    return np.atleast_1d(arr)


class Curve:
    """Base class: subclasses implement ``_eval(u, k)`` (the k-th derivative, k = 0..3)."""

    #: Natural parameter interval.
    domain: tuple[float, float] = (0.0, 1.0)
    #: True when ``point(domain[0]) == point(domain[1])`` with matching derivatives.
    closed: bool = False

    def _eval(self, u: np.ndarray, k: int) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def point(self, u: Param) -> Float64Array:
        """Points ``x(u)``, shape ``(k, 3)``."""
        return self._eval(_u(u), 0)

    def d1(self, u: Param) -> Float64Array:
        """First derivative ``x′(u)``, shape ``(k, 3)``."""
        return self._eval(_u(u), 1)

    def d2(self, u: Param) -> Float64Array:
        """Second derivative ``x″(u)``, shape ``(k, 3)``."""
        return self._eval(_u(u), 2)

    def d3(self, u: Param) -> Float64Array:
        """Third derivative ``x‴(u)``, shape ``(k, 3)``."""
        return self._eval(_u(u), 3)

    def parameters(self, n: int) -> Float64Array:
        """``n`` uniformly spaced parameters over :attr:`domain` (both ends included)."""
        n = as_int(n, "n", 2, MAX_SAMPLES, out_of_bounds=lambda x: (
            f"a sample count must be at least 2 and at most {MAX_SAMPLES:,}, got {x}"))
        return np.linspace(self.domain[0], self.domain[1], n)

    def sample(self, n: int) -> Float64Array:
        """``n`` points at uniformly spaced parameters over :attr:`domain`."""
        return self.point(self.parameters(n))

    def tangent(self, u: Param) -> Float64Array:
        """Unit tangents ``x′/|x′|``."""
        d = self.d1(u)
        out: Float64Array = d / np.linalg.norm(d, axis=1, keepdims=True)
        return out

    def curvature(self, u: Param) -> Float64Array:
        """Curvature ``κ = |x′ × x″| / |x′|³`` (1/length)."""
        d1, d2 = self.d1(u), self.d2(u)
        out: Float64Array = np.linalg.norm(np.cross(d1, d2), axis=1) / np.linalg.norm(d1, axis=1) ** 3
        return out

    def torsion(self, u: Param) -> Float64Array:
        """Torsion ``τ = det(x′, x″, x‴) / |x′ × x″|²`` (1/length; undefined where κ = 0)."""
        d1, d2, d3 = self.d1(u), self.d2(u), self.d3(u)
        c = np.cross(d1, d2)
        out: Float64Array = np.einsum("ij,ij->i", c, d3) / np.einsum("ij,ij->i", c, c)
        return out

    def speed(self, u: Param) -> Float64Array:
        """``|x′(u)|`` (length per unit parameter)."""
        out: Float64Array = np.linalg.norm(self.d1(u), axis=1)
        return out

    def frenet(self, u: Param) -> Float64Array:
        """Exact Frenet frames ``(k, 3, 3)``, columns ``(N, B, T)`` (undefined where κ = 0)."""
        d1, d2 = self.d1(u), self.d2(u)
        t = d1 / np.linalg.norm(d1, axis=1, keepdims=True)
        b = np.cross(d1, d2)
        b /= np.linalg.norm(b, axis=1, keepdims=True)
        n = np.cross(b, t)
        return np.stack([n, b, t], axis=2)

    def __repr__(self) -> str:
        fields = ", ".join(f"{k}={v!r}" for k, v in vars(self).items() if not k.startswith("_"))
        return f"{type(self).__name__}({fields})"


class Helix(Curve):
    """Circular helix ``(a cos u, a sin u, b u)``, ``u ∈ [0, 2π·turns]``.

    Arc length ``s = c u`` with ``c = √(a² + b²)``; ``κ = a/c²``, ``τ = b/c²``.
    """

    a: float
    b: float

    def __init__(self, a: float = 1.0, b: float = 0.5, turns: float = 1.0) -> None:
        a = as_finite(a, "a")
        if not a > 0:
            raise ValueError(f"a: the helix radius must be positive and finite, got {a!r}")
        self.a, self.b = a, as_finite(b, "b")
        self.domain = (0.0, 2 * math.pi * as_positive(turns, "turns"))

    def _eval(self, u: np.ndarray, k: int) -> np.ndarray:
        a, b = self.a, self.b
        c, s = np.cos(u), np.sin(u)
        z = np.zeros_like(u)
        if k == 0:
            return np.stack([a * c, a * s, b * u], axis=1)
        if k == 1:
            return np.stack([-a * s, a * c, np.full_like(u, b)], axis=1)
        if k == 2:
            return np.stack([-a * c, -a * s, z], axis=1)
        return np.stack([a * s, -a * c, z], axis=1)

    def rmf(self, u: Param, angle: float = 0.0) -> Float64Array:
        """Exact rotation-minimising frames ``(k, 3, 3)`` (columns ``r, s, t``).

        ``r(u) = cos θ N + sin θ B`` with ``θ = angle − τ c (u − u_0)``: the Frenet frame
        turned back by the integrated torsion (Wang et al. 2008, Eq. 3). ``angle`` is the
        angle of ``r`` from the principal normal ``N`` at ``u[0]``.
        """
        angle = as_finite(angle, "angle")
        uu = _u(u)
        f = self.frenet(uu)
        c = math.hypot(self.a, self.b)
        theta = angle - (self.b / c**2) * c * (uu - uu[0])
        r = np.cos(theta)[:, None] * f[:, :, 0] + np.sin(theta)[:, None] * f[:, :, 1]
        t = f[:, :, 2]
        return np.stack([r, np.cross(t, r), t], axis=2)


class TorusKnot(Curve):
    """``((R + r cos qu) cos pu, (R + r cos qu) sin pu, r sin qu)``, ``u ∈ [0, 2π]``.

    The defaults (p, q, R, r) = (2, 7, 0.6, 0.3) are the torus knot of Wang et al. (2008).
    """

    p: int
    q: int
    R: float
    r: float

    closed = True

    def __init__(self, p: int = 2, q: int = 7, R: float = 0.6, r: float = 0.3) -> None:
        # positive integers: the curve closes after u = 2π only then
        p, q = (as_int(v, k, 1, _MAX_WINDINGS, out_of_bounds=lambda x: (
            f"the winding number must be a positive integer at most {_MAX_WINDINGS:,}, got {x}"))
            for v, k in ((p, "p"), (q, "q")))
        R, r = as_finite(R, "R"), as_finite(r, "r")
        if not (R > 0 and r > 0):
            raise ValueError("R, r: radii must be positive")
        self.p, self.q, self.R, self.r = p, q, R, r
        self.domain = (0.0, 2 * math.pi)

    def _eval(self, u: np.ndarray, k: int) -> np.ndarray:
        p, q, R, r = self.p, self.q, self.R, self.r
        cq, sq = np.cos(q * u), np.sin(q * u)
        cp, sp = np.cos(p * u), np.sin(p * u)
        rho = [R + r * cq, -r * q * sq, -r * q**2 * cq, r * q**3 * sq]
        z = [r * sq, r * q * cq, -r * q**2 * sq, -r * q**3 * cq][k]
        # Leibniz rule for rho(u) * (cos pu, sin pu)
        x = np.zeros_like(u)
        y = np.zeros_like(u)
        for j in range(k + 1):
            m = k - j
            w = math.comb(k, j) * p**m
            # m-th derivative of (cos pu, sin pu) = p^m (cos(pu + mπ/2), sin(pu + mπ/2))
            cm = [cp, -sp, -cp, sp][m % 4]
            sm = [sp, cp, -sp, -cp][m % 4]
            x = x + w * rho[j] * cm
            y = y + w * rho[j] * sm
        return np.stack([x, y, z], axis=1)


class Viviani(Curve):
    """Viviani's curve ``a (1 + cos u, sin u, 2 sin(u/2))``, ``u ∈ [0, 4π]``.

    It lies on the sphere of radius ``2a`` about the origin, so its rotation-minimising frame
    is ``r = x/|x|`` (the sphere normal) up to a constant rotation about the tangent.
    """

    a: float

    closed = True

    def __init__(self, a: float = 1.0) -> None:
        self.a = as_positive(a, "a")
        self.domain = (0.0, 4 * math.pi)

    def _eval(self, u: np.ndarray, k: int) -> np.ndarray:
        a = self.a
        c, s = np.cos(u), np.sin(u)
        c2, s2 = np.cos(u / 2), np.sin(u / 2)
        cols = [
            (1 + c, s, 2 * s2),
            (-s, c, c2),
            (-c, -s, -0.5 * s2),
            (s, -c, -0.25 * c2),
        ][k]
        return a * np.stack(np.broadcast_arrays(*cols), axis=1)


class Polynomial(Curve):
    """Polynomial curve ``x(u) = Σ_j c_j u^j`` with coefficient rows ``c_j`` (shape (d+1, 3))."""

    coefficients: Float64Array

    def __init__(
        self, coefficients: Array, domain: tuple[float, float] = (0.0, 1.0)
    ) -> None:
        c = as_float_array(coefficients, "coefficients")
        if c.ndim != 2 or c.shape[1] != 3 or c.shape[0] < 2:
            raise ValueError(f"coefficients: expected shape (d+1, 3) with d >= 1, got {c.shape}")
        if not np.all(np.isfinite(c)):
            raise ValueError("coefficients: contains non-finite values")
        self.coefficients = c.copy()
        d = as_float_array(domain, "domain")
        if d.shape != (2,) or not np.all(np.isfinite(d)) or not d[1] > d[0]:
            raise ValueError(f"domain: expected two finite values lo < hi, got {domain!r}")
        self.domain = (float(d[0]), float(d[1]))

    def _eval(self, u: np.ndarray, k: int) -> np.ndarray:
        c = self.coefficients
        d = c.shape[0] - 1
        out = np.zeros((u.shape[0], 3))
        for j in range(k, d + 1):
            f = math.perm(j, k)
            out += f * np.power.outer(u, j - k)[:, None] * c[j]
        return out


class Bezier(Polynomial):
    """Bézier curve on ``u ∈ [0, 1]`` with control points of shape ``(d+1, 3)``."""

    control_points: Float64Array

    def __init__(self, control_points: Array) -> None:
        p = as_float_array(control_points, "control_points")
        if p.ndim != 2 or p.shape[1] != 3 or p.shape[0] < 2:
            raise ValueError(f"control_points: expected shape (d+1, 3), d >= 1, got {p.shape}")
        if not np.all(np.isfinite(p)):
            bad = int(np.flatnonzero(~np.isfinite(p).all(axis=1))[0])
            raise ValueError(f"control_points: non-finite value at row {bad}")
        d = p.shape[0] - 1
        # power-basis coefficients: c_j = C(d, j) Σ_i (-1)^(j-i) C(j, i) P_i
        coeffs = np.array(
            [
                math.comb(d, j)
                * sum((-1) ** (j - i) * math.comb(j, i) * p[i] for i in range(j + 1))
                for j in range(d + 1)
            ]
        )
        super().__init__(coeffs, (0.0, 1.0))
        self.control_points = p.copy()


class Spline(Curve):
    r"""A cubic spline through (or, ``kind="bspline"``, shaped by) control points.

    Parameters
    ----------
    points : array_like (n, 3)
        The control points (any real dtype; never modified). With ``closed=True`` a last
        row equal to the first (a repeated first point, as :func:`spinal.frames` accepts it)
        is dropped.
    kind : {"catmull_rom", "natural_cubic", "bspline"}
        The spline, below.
    closed : bool
        A periodic spline through the loop ``p_0 … p_{n−1}, p_0``.

    Attributes
    ----------
    points : ndarray (n, 3)
        The control points (read-only copy).
    kind : str
    closed : bool
    knots : ndarray (m + 1,)
        The parameters where the cubic pieces meet (``knots[0], knots[-1]`` = :attr:`domain`).
    domain : tuple of float

    Raises
    ------
    ValueError
        ``points`` not of shape (n, 3), with NaN/inf, or too few of them (``catmull_rom``
        and ``natural_cubic``: 2, closed 3; ``bspline``: 4, closed 3); consecutive equal
        points for the interpolating kinds (a chord of length 0); an unknown ``kind``.
    TypeError
        ``closed`` not a bool.

    Notes
    -----
    *Parameter.* The interpolating kinds use the chord-length parametrisation: the knots are
    ``t_0 = 0``, ``t_{i+1} = t_i + h_i`` with ``h_i = |p_{i+1} − p_i|`` (closed: with the
    chord ``h_{n−1} = |p_0 − p_{n−1}|`` back to the start), ``x(t_i) = p_i`` and
    ``domain = (0, t_last)``: the length of the control polygon. The speed ``|x′|`` is
    near 1 where the points are dense for the curvature (exactly 1 on straight runs), so
    ``u`` approximates arc length. The B-spline has uniform knots and
    ``domain = (0, number of pieces)``: ``(0, n − 3)`` open, ``(0, n)`` closed.

    ``kind="natural_cubic"``: the C² cubic spline interpolant with natural ends
    ``x″(t_0) = x″(t_{n−1}) = 0`` (closed: periodic, C² at the seam too). Its second
    derivatives ``M_i`` at the knots solve the tridiagonal system
    ``h_{i−1} M_{i−1} + 2(h_{i−1} + h_i) M_i + h_i M_{i+1} = 6(δ_i − δ_{i−1})``,
    ``δ_i = (p_{i+1} − p_i)/h_i`` (cyclic when closed), solved by the Thomas algorithm
    (Sherman–Morrison for the cyclic one). de Boor (2001), Ch. IV; Press et al. (2007),
    §2.4 and §2.7.2. Equal to ``scipy.interpolate.CubicSpline(knots, points,
    bc_type="natural")`` (closed: ``"periodic"`` with the first point appended).

    ``kind="catmull_rom"``: the C¹ cubic Hermite interpolant (de Boor, Ch. IV) whose slope
    at ``t_i`` is that of the parabola through ``p_{i−1}, p_i, p_{i+1}`` at
    ``t_{i−1}, t_i, t_{i+1}`` (Bessel's slope),

    .. math:: m_i = \frac{h_i\,\delta_{i-1} + h_{i-1}\,\delta_i}{h_{i-1} + h_i}.

    This is the non-uniform Catmull–Rom spline of Barry & Goldman (1988) with the chordal
    knots: their pyramid blends the two parabolas through ``p_{i−1}, p_i, p_{i+1}`` and
    ``p_i, p_{i+1}, p_{i+2}`` linearly over ``[t_i, t_{i+1}]``, which is this cubic (same
    end values, and at ``t_i`` the slope of the first parabola). On equal chords ``h`` it
    is the spline of Catmull & Rom (1974), ``m_i = (p_{i+1} − p_{i−1})/(2h)``. Open ends take the
    slope at the end point of the parabola through the three end points,
    ``m_0 = ((2h_0 + h_1) δ_0 − h_0 δ_1)/(h_0 + h_1)`` (two points: the straight chord);
    closed curves take the neighbours round the loop. Points on a straight line give the
    line at speed 1, whatever their spacing.

    ``kind="bspline"``: the approximating cubic B-spline ``x(u) = Σ_k p_k N_{k,3}(u)``
    (de Boor, Ch. IX–X; Piegl & Tiller 1997, §2). Open: clamped, on the knot vector
    ``[0, 0, 0, 0, 1, …, n−4, n−3, n−3, n−3, n−3]``, so it starts at ``p_0`` tangent to
    ``p_1 − p_0`` and ends at ``p_{n−1}`` (``scipy.interpolate.BSpline(knots, points, 3)``).
    Closed: the uniform periodic B-spline of the control polygon, C² everywhere, with
    ``x(i) = (p_{i−1} + 4p_i + p_{i+1})/6`` (indices modulo n; the same as ``BSpline`` on
    the knots ``−3 … n+3`` with the control points ``p_{n−1}, p_0, …, p_{n−1}, p_0, p_1``).

    Every kind is stored as ``m`` cubics in the power basis of ``s = u − knots[i]``, so
    :meth:`point` and the exact derivatives :meth:`d1`, :meth:`d2`, :meth:`d3` are one
    binary search and a Horner scheme per call (vectorised; a million values in tens of
    milliseconds). An open spline refuses ``u`` outside :attr:`domain` (beyond 1e-12 of its
    length); a closed one wraps ``u`` periodically.

    *Arc length.* :attr:`length` and :meth:`arc_length_parameters` integrate ``|x′|`` over
    each piece by 16-point Gauss–Legendre quadrature, halving the intervals where the rule
    and its two halves differ by more than 1e-13 relative (near cusps of a B-spline), and
    invert ``s(u)`` by Newton's method safeguarded by bisection.

    References
    ----------
    C. de Boor, *A Practical Guide to Splines*, rev. ed., Springer 2001, Ch. IV, IX, X.
    E. Catmull, R. Rom, *A class of local interpolating splines*, in Computer Aided
    Geometric Design (Barnhill & Riesenfeld, eds.), Academic Press 1974, 317–326.
    P. J. Barry, R. N. Goldman, *A recursive evaluation algorithm for a class of
    Catmull–Rom splines*, SIGGRAPH '88, Computer Graphics 22(4), 199–204, 1988.
    L. Piegl, W. Tiller, *The NURBS Book*, 2nd ed., Springer 1997, §2.
    W. H. Press et al., *Numerical Recipes*, 3rd ed., Cambridge 2007, §2.4, §2.7.2.

    Examples
    --------
    >>> import numpy as np
    >>> from spinal.curves import Spline
    >>> a = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    >>> ring = Spline(np.column_stack([np.cos(a), np.sin(a), 0 * a]), "natural_cubic",
    ...               closed=True)
    >>> round(ring.length, 4)  # 2π up to the interpolation error
    6.2832
    >>> ring.sample_arc_length(100).shape  # closed: the first point is not repeated
    (100, 3)
    """

    points: Float64Array
    kind: Literal["catmull_rom", "natural_cubic", "bspline"]
    closed: bool
    knots: Float64Array

    def __init__(
        self,
        points: Array,
        kind: Literal["catmull_rom", "natural_cubic", "bspline"] = "catmull_rom",
        closed: bool = False,
    ) -> None:
        kind = as_choice(kind, "kind", _SPLINE_KINDS)
        closed = as_bool(closed, "closed")
        p = as_float_array(points, "points")
        if p.ndim != 2 or p.shape[1] != 3:
            raise ValueError(f"points: expected an array of shape (n, 3), got shape {p.shape}")
        finite = np.isfinite(p).all(axis=1)
        if not finite.all():
            raise ValueError(f"points: non-finite value at row {int(np.argmin(finite))}")
        if closed and len(p) > 1 and np.array_equal(p[0], p[-1]):
            p = p[:-1]  # a repeated first point closes the loop already
        least = (3 if closed else 4) if kind == "bspline" else (3 if closed else 2)
        if len(p) < least:
            raise ValueError(f"points: kind={kind!r} needs at least {least} points"
                             f"{' when closed' if closed else ''}, got {len(p)}")
        p = np.array(p, dtype=np.float64, order="C")  # our own copy
        if kind == "bspline":
            knots, c = periodic_bspline(p) if closed else bspline_pieces(
                clamped_knots(len(p)), p)
        else:
            _, h, d = chords(p, closed)
            loop = np.vstack([p, p[:1]]) if closed else p
            knots = np.concatenate([[0.0], np.cumsum(h)])
            c = (natural_pieces(loop, h, d, closed) if kind == "natural_cubic"
                 else hermite_pieces(loop, catmull_rom_slopes(h, d, closed), h, d))
        p.setflags(write=False)
        knots.setflags(write=False)
        self.points, self.kind, self.closed, self.knots = p, kind, closed, knots
        self.domain = (float(knots[0]), float(knots[-1]))
        self._coef = derivative_coefficients(c)
        self._table: ArcTable | None = None  # the arc-length table, built when first needed

    def _eval(self, u: np.ndarray, k: int) -> np.ndarray:
        lo, hi = self.domain
        if self.closed:
            u = lo + np.mod(u - lo, hi - lo)
            # a whole number of periods that rounds to just short of one is the seam (the
            # start of the first piece), as it is in exact arithmetic
            u = np.where(u - lo > (hi - lo) * (1 - 4 * np.finfo(float).eps), lo, u)
        else:
            slack = 1e-12 * max(hi - lo, abs(lo), abs(hi))
            out = (u < lo - slack) | (u > hi + slack)
            if out.any():
                raise ValueError(f"u: {float(u[out][0])!r} is outside the domain [{lo!r}, {hi!r}] of "
                                 f"this open spline")
        piece = np.clip(np.searchsorted(self.knots, u, side="right") - 1, 0,
                        len(self.knots) - 2)
        return horner(self._coef[k], piece, u - self.knots[piece])

    def _speed(self, piece: np.ndarray, s: np.ndarray) -> np.ndarray:
        """``|x′|`` on ``piece`` at the local parameter ``s``."""
        return row_norms(horner(self._coef[1], piece, s))

    def _arc_table(self) -> ArcTable:
        if self._table is None:
            self._table = arc_length_table(self._speed, np.diff(self.knots))
        return self._table

    @property
    def length(self) -> float:
        """The arc length ``∫|x′| du`` over :attr:`domain` (closed: once round the loop)."""
        return float(self._arc_table()[3][-1])

    def arc_length_parameters(self, n: int) -> Float64Array:
        """``n`` parameters ``u`` at equal arc-length steps, increasing.

        Open: both ends included, ``s(u_i) = i L/(n − 1)``. Closed: ``s(u_i) = i L/n``,
        ``i = 0 … n − 1``, the start not repeated at the end (like
        :meth:`sample_arc_length`); for ``spinal.frames(spline, u=..., closed=True)``, which
        needs ``u`` to span the whole period, append ``domain[1]``."""
        n = as_int(n, "n", 2, MAX_SAMPLES, out_of_bounds=lambda x: (
            f"a sample count must be at least 2 and at most {MAX_SAMPLES:,}, got {x}"))
        table = self._arc_table()
        total = table[3][-1]
        targets = (total / n * np.arange(n) if self.closed
                   else np.linspace(0.0, total, n))
        piece, s = invert_arc_length(self._speed, table, targets)
        u = self.knots[piece] + s
        u[0] = self.domain[0]
        if not self.closed:
            u[-1] = self.domain[1]
        out: Float64Array = np.clip(u, *self.domain)
        return out

    def sample_arc_length(self, n: int) -> Float64Array:
        """``n`` points equally spaced in arc length, ``(n, 3)``:
        ``point(arc_length_parameters(n))``. Open: both end points included. Closed: the
        first point is not repeated at the end, as ``spinal.frames``, ``spinal.tube`` and
        ``spinal.sweep`` take closed polylines (with ``closed=True``)."""
        return self.point(self.arc_length_parameters(n))

    def __repr__(self) -> str:
        return (f"Spline(<{len(self.points)} points>, kind={self.kind!r}, "
                f"closed={self.closed!r})")
