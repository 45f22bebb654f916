"""The implementation of :mod:`spinal.curves` (see its documentation); the public names are
re-exported there."""

from __future__ import annotations

import math

import numpy as np

from ._validate import MAX_SAMPLES, as_finite, as_float_array, as_int, as_positive

#: The largest winding number of a :class:`TorusKnot` (its third derivative grows as ``q³``).
_MAX_WINDINGS = 1_000_000


def _u(u) -> np.ndarray:
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

    def point(self, u) -> np.ndarray:
        """Points ``x(u)``, shape ``(k, 3)``."""
        return self._eval(_u(u), 0)

    def d1(self, u) -> np.ndarray:
        """First derivative ``x′(u)``, shape ``(k, 3)``."""
        return self._eval(_u(u), 1)

    def d2(self, u) -> np.ndarray:
        """Second derivative ``x″(u)``, shape ``(k, 3)``."""
        return self._eval(_u(u), 2)

    def d3(self, u) -> np.ndarray:
        """Third derivative ``x‴(u)``, shape ``(k, 3)``."""
        return self._eval(_u(u), 3)

    def parameters(self, n: int) -> np.ndarray:
        """``n`` uniformly spaced parameters over :attr:`domain` (both ends included)."""
        n = as_int(n, "n", 2, MAX_SAMPLES, out_of_bounds=lambda x: (
            f"a sample count must be at least 2 and at most {MAX_SAMPLES:,}, got {x}"))
        return np.linspace(self.domain[0], self.domain[1], n)

    def sample(self, n: int) -> np.ndarray:
        """``n`` points at uniformly spaced parameters over :attr:`domain`."""
        return self.point(self.parameters(n))

    def tangent(self, u) -> np.ndarray:
        """Unit tangents ``x′/|x′|``."""
        d = self.d1(u)
        return d / np.linalg.norm(d, axis=1, keepdims=True)

    def curvature(self, u) -> np.ndarray:
        """Curvature ``κ = |x′ × x″| / |x′|³`` (1/length)."""
        d1, d2 = self.d1(u), self.d2(u)
        return np.linalg.norm(np.cross(d1, d2), axis=1) / np.linalg.norm(d1, axis=1) ** 3

    def torsion(self, u) -> np.ndarray:
        """Torsion ``τ = det(x′, x″, x‴) / |x′ × x″|²`` (1/length; undefined where κ = 0)."""
        d1, d2, d3 = self.d1(u), self.d2(u), self.d3(u)
        c = np.cross(d1, d2)
        return np.einsum("ij,ij->i", c, d3) / np.einsum("ij,ij->i", c, c)

    def speed(self, u) -> np.ndarray:
        """``|x′(u)|`` (length per unit parameter)."""
        return np.linalg.norm(self.d1(u), axis=1)

    def frenet(self, u) -> np.ndarray:
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

    def __init__(self, a: float = 1.0, b: float = 0.5, turns: float = 1.0):
        a = as_finite(a, "a")
        if not a > 0:
            raise ValueError(f"a: the helix radius must be positive and finite, got {a!r}")
        self.a, self.b = a, as_finite(b, "b")
        self.domain = (0.0, 2 * math.pi * as_positive(turns, "turns"))

    def _eval(self, u, k):
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

    def rmf(self, u, angle: float = 0.0) -> np.ndarray:
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

    closed = True

    def __init__(self, p: int = 2, q: int = 7, R: float = 0.6, r: float = 0.3):
        # positive integers: the curve closes after u = 2π only then
        p, q = (as_int(v, k, 1, _MAX_WINDINGS, out_of_bounds=lambda x: (
            f"the winding number must be a positive integer at most {_MAX_WINDINGS:,}, got {x}"))
            for v, k in ((p, "p"), (q, "q")))
        R, r = as_finite(R, "R"), as_finite(r, "r")
        if not (R > 0 and r > 0):
            raise ValueError("R, r: radii must be positive")
        self.p, self.q, self.R, self.r = p, q, R, r
        self.domain = (0.0, 2 * math.pi)

    def _eval(self, u, k):
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

    closed = True

    def __init__(self, a: float = 1.0):
        self.a = as_positive(a, "a")
        self.domain = (0.0, 4 * math.pi)

    def _eval(self, u, k):
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

    def __init__(self, coefficients, domain: tuple[float, float] = (0.0, 1.0)):
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

    def _eval(self, u, k):
        c = self.coefficients
        d = c.shape[0] - 1
        out = np.zeros((u.shape[0], 3))
        for j in range(k, d + 1):
            f = math.perm(j, k)
            out += f * np.power.outer(u, j - k)[:, None] * c[j]
        return out


class Bezier(Polynomial):
    """Bézier curve on ``u ∈ [0, 1]`` with control points of shape ``(d+1, 3)``."""

    def __init__(self, control_points):
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
