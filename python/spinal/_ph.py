"""The implementation of :mod:`spinal.ph` (see its documentation); the public names are
re-exported there."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Literal, overload

import numpy as np
import numpy.typing as npt

from . import _core
from ._ph_bezier import (
    _finite,
    _rational_numerators,
    _section,
    _straighten,
    _sweep_patches,
)
from ._ph_fit import (
    _MAX_FIT_SEGMENTS,
    _REASONS,
    _dev_curve,
    _dev_rows,
    _fixed_knots,
    _hermite_batch,
    _initial_knots,
)
from ._types import Array, Float64Array, Param
from ._validate import MAX_SAMPLES, as_bool, as_finite, as_float_array, as_int, as_positive, as_real

if TYPE_CHECKING:
    from ._curves import Curve
    from ._mesh import Mesh


def _vectors(x: Any, name: str, width: int = 3) -> tuple[np.ndarray, bool]:
    """``(width,)`` or ``(m, width)`` -> a C-contiguous ``(m, width)`` array and 'was single'."""
    a = as_float_array(x, name)
    if a.shape == (width,):
        return np.ascontiguousarray(a[None]), True
    if a.ndim == 2 and a.shape[1] == width:
        return np.ascontiguousarray(a), False
    raise ValueError(f"{name}: expected shape ({width},) or (m, {width}), got {a.shape}")


def _cubics(x: Any, name: str = "control_points") -> tuple[np.ndarray, bool]:
    """``(4, 3)`` or ``(m, 4, 3)`` control points -> ``(m, 4, 3)`` and 'was single'."""
    a = as_float_array(x, name)
    if a.shape == (4, 3):
        return np.ascontiguousarray(a[None]), True
    if a.ndim == 3 and a.shape[1:] == (4, 3):
        return np.ascontiguousarray(a), False
    raise ValueError(f"{name}: expected shape (4, 3) or (m, 4, 3), got {a.shape}")


@overload
def hermite(
    p0: Array, t0: Array, p1: Array, t1: Array, *, all: Literal[False] = False
) -> Float64Array: ...


@overload
def hermite(
    p0: Array, t0: Array, p1: Array, t1: Array, *, all: Literal[True]
) -> Float64Array | list[Float64Array]: ...


@overload
def hermite(
    p0: Array, t0: Array, p1: Array, t1: Array, *, all: bool = False
) -> Float64Array | list[Float64Array]: ...


def hermite(
    p0: Array, t0: Array, p1: Array, t1: Array, *, all: bool = False
) -> Float64Array | list[Float64Array]:
    """G¹ Hermite interpolation by a PH cubic (Mäurer & Jüttler §3.2, Table 1, signed).

    Finds the PH cubics from ``p0`` to ``p1`` whose end tangents point along ``t0`` and
    ``t1`` (normalised here; lengths are ignored). With ``C = t0·t1``, ``D = p1 − p0`` and the
    feet ``n₁ = p0 + λ₁t0``, ``n₂ = p1 + λ₂t1`` of the common perpendicular of the tangent
    lines, the inner control points are ``b₁ = n₁ − X t0``, ``b₂ = n₂ + X t1`` where ``X``
    solves the *signed* equation (the printed one with ``|λᵢ|`` is wrong when λ₁ < 0 or
    λ₂ > 0)::

        (λ₁ − X)(−λ₂ − X) − 2(1 + C)X² = 2|n₁ − n₂|²/(1 − C)

    and gives a forward polygon, ``L₁ = λ₁ − X > 0`` and ``L₃ = −λ₂ − X > 0``. (It is solved
    in an equivalent form for the mean leg ``(L₁ + L₃)/2`` that stays accurate for nearly
    parallel or antiparallel tangents, where ``λ₁, λ₂ ~ 1/(1 − C²)`` would cancel.) There are 0, 1
    or 2 solutions; the one with the shortest control polygon is the shape-matching one for
    data sampled from a smooth curve (``X ≈ h/6``). Special cases: ``C = −1/2`` (the
    equation is linear: at most one solution); parallel tangents, ``|t0 − t1| < 1e-8``
    (only a straight line interpolates, when the chord is along the tangents: the uniform
    line); ``C = −1`` (the equation becomes the planar closed form
    ``L₁ = (d + √(d² + 4e²))/2``, ``L₃ = L₁ − d``, ``d = D·t0``, ``e = |D − d t0|``; no
    solution when ``p1`` is on the tangent line, ``e = 0``).

    Parameters
    ----------
    p0, t0, p1, t1 : array_like (3,) or (m, 3)
        End points and end tangents (one data set, or ``m`` of them).
    all : bool
        Return every solution, shortest polygon first, instead of the best one; never
        raises for "no solution" (the list is then empty).

    Returns
    -------
    ndarray
        ``all=False``: control points ``(4, 3)`` (or ``(m, 4, 3)``). ``all=True``: ``(k, 4, 3)``
        with ``k ∈ {0, 1, 2}`` for one data set, a list of those for ``m`` data sets.

    Raises
    ------
    ValueError
        Non-finite input, a zero tangent, ``p1 == p0``; with ``all=False`` data without a
        solution, saying why: parallel end tangents with the chord not along them,
        S-shaped data / an inflection inside / too long a segment (negative discriminant
        or only reversed polygons) — split the segment.
    """
    all_ = as_bool(all, "all")
    a0, s0 = _vectors(p0, "p0")
    a1, _ = _vectors(t0, "t0")
    a2, _ = _vectors(p1, "p1")
    a3, _ = _vectors(t1, "t1")
    m = a0.shape[0]
    for name, arr in (("t0", a1), ("p1", a2), ("t1", a3)):
        if arr.shape[0] != m:
            raise ValueError(f"{name}: expected {m} rows like p0, got {arr.shape[0]}")
    single = s0 and m == 1
    cand, counts, _ = _core.ph_hermite(a0, a1, a2, a3, all_, not single)
    cand = cand.reshape(m, 2, 4, 3)
    if not all_:
        out = np.ascontiguousarray(cand[:, 0])
        return out[0] if single else out
    lists = [np.ascontiguousarray(cand[i, : counts[i]]) for i in range(m)]
    return lists[0] if single else lists


def is_ph(control_points: Array, tol: float = 1e-9) -> bool | npt.NDArray[np.bool_]:
    """Control-polygon test for PH cubics (Maurer & Jüttler (17)).

    A cubic is PH iff the angles ``θ₁₂ = ∠(d₁, d₂)`` and ``θ₂₃ = ∠(d₂, d₃)`` agree and
    ``cos ψ = 2L₂²/(L₁L₃) − 1`` with ``ψ = ∠(d₁ × d₂, d₂ × d₃)``; both are tested on cosines
    within ``tol``. Planar bent polygons are PH iff the angles agree and ``L₂² = L₁L₃``
    (convex, Tschirnhausen cubics); straight polygons run forwards iff ``L₂² ≤ L₁L₃`` (they
    then have a quaternion preimage). Polygons with a zero-length leg return False.

    Returns a bool for ``(4, 3)`` input, a bool array ``(m,)`` for ``(m, 4, 3)``.
    """
    cp, single = _cubics(control_points)
    out = _core.ph_is_ph(cp, as_real(tol, "tol"))  # value: the core
    return bool(out[0]) if single else out


def from_quaternions(
    A0: Array, A1: Array, start: Array = (0.0, 0.0, 0.0), *, scalar_first: bool = False
) -> Float64Array:
    """The PH cubic with the quaternion preimage ``A(v) = A0(1 − v) + A1 v``.

    Its hodograph is ``x′(v) = A(v) i A(v)*`` (vector part), so ``σ = |A|²``. Control points
    (the quaternion form of spatial PH curves): ``b₁ = b₀ + A0 i A0*/3``,
    ``b₂ = b₁ + (A0 i A1* + A1 i A0*)/6``, ``b₃ = b₂ + A1 i A1*/3`` with ``b₀ = start``.
    ``A0``, ``A1``: ``(4,)`` or ``(m, 4)`` quaternions, ``(x, y, z, w)`` unless
    ``scalar_first``. Returns ``(4, 3)`` or ``(m, 4, 3)``.
    """
    sf = as_bool(scalar_first, "scalar_first")
    q0, single = _vectors(A0, "A0", 4)
    q1, _ = _vectors(A1, "A1", 4)
    if q1.shape != q0.shape:
        raise ValueError(f"A1: expected the shape of A0 {q0.shape}, got {q1.shape}")
    st, _ = _vectors(start, "start")
    if st.shape[0] not in (1, q0.shape[0]):
        raise ValueError(f"start: expected (3,) or ({q0.shape[0]}, 3), got {st.shape}")
    # the core reads (x, y, z, w) rows in place (no reordered copy) and the one start for all
    out = _core.ph_from_quaternions(q0, q1, st, sf).reshape(-1, 4, 3)
    return out[0] if single else out


def preimage(
    control_points: Array, *, scalar_first: bool = False, tol: float = 1e-9
) -> tuple[Float64Array, Float64Array]:
    """Quaternion preimage ``(A0, A1)`` of a PH cubic (inverse of :func:`from_quaternions`).

    ``A0`` is the root of ``A i A* = 3d₁`` that rotates ``x̂`` onto ``d₁`` along the shortest
    arc (scaled by ``√|3d₁|``); ``A1`` is a root of ``3d₃`` turned about ``i`` by the angle
    that reproduces ``d₂`` (least squares). The preimage is unique up to
    ``A → A(cos φ + i sin φ)`` and a global sign. Raises ValueError when the regenerated
    control points differ from the input by more than ``tol`` times the polygon length
    (the cubic is not PH). Returns ``(A0, A1)``, each ``(4,)`` or ``(m, 4)``.
    """
    sf = as_bool(scalar_first, "scalar_first")
    tol = as_positive(tol, "tol")
    cp, single = _cubics(control_points)
    rows = _core.ph_preimage(cp, tol, not single, sf)  # in the order asked for
    q0, q1 = np.ascontiguousarray(rows[:, 0:4]), np.ascontiguousarray(rows[:, 4:8])
    return (q0[0], q1[0]) if single else (q0, q1)


_INV_KEYS = ("L1", "L2", "L3", "cos_theta", "sin_theta", "delta", "a", "b", "c", "k",
             "kappa_over_tau", "sigma_min", "kappa_max")


def invariants(control_points: Array) -> dict[str, Any]:
    """Scalar invariants of a PH cubic (Mäurer & Jüttler (18), (31); torsion signed by ``Δ``).

    Keys: ``L1, L2, L3`` (leg lengths), ``cos_theta, sin_theta`` (``θ = ∠(d₁, d₂)``),
    ``delta = det[d₁, d₂, d₃]``, ``a, b, c`` (``σ = 3((cv − b)² + a²)/c``), ``k`` (the factor
    of the RMF angle, ``|k| ≤ 1``, 0 when planar), ``kappa_over_tau`` (constant ``κ/τ``,
    signed like τ; ``inf`` when planar), ``sigma_min`` (smallest speed on [0, 1]) and
    ``kappa_max = 6L₂sθ/σ_min²``. Values are floats for ``(4, 3)`` input, ``(m,)`` arrays
    for ``(m, 4, 3)``. The input is assumed PH (check with :func:`is_ph`); a control polygon
    with a zero-length leg, or whose invariants are undefined, raises ValueError.
    """
    cp, single = _cubics(control_points)
    rows = _core.ph_invariants(cp)
    return {k: (float(rows[0, i]) if single else rows[:, i].copy())
            for i, k in enumerate(_INV_KEYS)}


def evaluate(control_points: Array, v: float | Array, derivative: int = 0) -> Float64Array:
    """Points (``derivative=0``) or derivatives ``dᵏx/dvᵏ`` (k ≤ 3) of one cubic at ``v``.

    ``control_points`` (4, 3); ``v`` a float or ``(n,)`` in [0, 1]. Returns ``(n, 3)``.
    """
    cp, single = _cubics(control_points)
    if not single:
        raise ValueError("control_points: expected one cubic (4, 3); use PHSpline for many")
    return PHSpline._trusted(cp, np.arange(2.0)).evaluate(v, derivative)


_FIT_KEYS = ("straight", "omega0", "omega1", "k", "a", "b", "c", "phi", "sg", "lambda",
             "lambda_star", "I_min")


def _fit_dict(rows: np.ndarray, single: bool) -> dict[str, Any]:
    d = {key: rows[:, i].copy() for i, key in enumerate(_FIT_KEYS)}
    d["straight"] = d["straight"].astype(bool)
    d["beta"] = rows[:, 12:15].copy()
    d["gamma"] = rows[:, 15:18].copy()
    d["w"] = rows[:, 21:23].copy()
    d["slopes"] = rows[:, 23:25].copy()
    d["preimage"] = rows[:, 25:33].reshape(-1, 2, 4).copy()
    d["erf_angle"] = rows[:, 33].copy()
    if single:
        d = {k: (v[0].item() if v.ndim == 1 else v[0]) for k, v in d.items()}
    return d


def angle_fit(
    control_points: Array, *, omega_start: float = 0.0, phi: float | None = None
) -> dict[str, Any]:
    """The rational approximation of the RMF angle on one PH cubic (MJ (34)–(41)).

    ``Ω(0) = omega_start`` (radians from ``n`` towards ``b``). With ``sg = sign k`` and the
    offset ``phi`` (default: centred, ``(Ω(0) + Ω(1))/2``), ``w = sg·tan((Ω − φ)/2)`` is
    replaced by the rational quadratic (Bernstein coefficients ``γ/β``)::

        W(v) = (γ₀B₀² + γ₁B₁² + γ₂B₂²)/(β₀B₀² + β₁B₁² + β₂B₂²)
        β = (s₁, s₁(λ+2)/2, (w₁ − w₀)(λ+2) − s₀),  γ = (w₀β₀, s₁(w₀(λ+2) + s₀)/2, w₁β₂)

    which interpolates ``w`` and its slopes ``s`` at both ends for every ``λ``; ``λ`` minimises
    ``Î(λ) = ∫₀¹ (2W′/(1 + W²) − sg Ω′)² dv`` (Simpson, 20 subintervals) over
    ``λ > λ* = s₀/(w₁ − w₀) − 2`` (no pole, ``W′ > 0``). The approximate angle is
    ``Ω̃ = φ + 2 sg arctan W`` and ``max|Ω̃ − Ω| ≤ √I``. ``λ`` depends on ``φ`` and
    ``omega_start``; ``I_min`` and ``Ω̃`` do not. Planar cubics (``k = 0``) get ``W ≡ 0``,
    ``φ = Ω(0)``.

    Returns a dict: ``omega0, omega1, k, a, b, c, phi, sg, lambda, lambda_star, I_min,
    beta (3,), gamma (3,), w (w₀, w₁), slopes (s₀, s₁), straight``, and the quaternion
    preimage ``preimage (2, 4)`` (scalar first) with ``erf_angle``, the constant angle of
    ``n`` from the Euler–Rodrigues ``e₂`` towards ``e₃`` (see :meth:`PHSpline.frenet`).
    """
    cp, single = _cubics(control_points)
    if not single:
        raise ValueError("control_points: expected one cubic (4, 3); use PHSpline.angle_fit")
    _core.ph_check_spline(cp, np.arange(2.0), True)
    om = as_finite(omega_start, "omega_start")
    ph = None if phi is None else as_finite(phi, "phi")
    rows = _core.ph_frame_setup(cp, None, om, ph)
    return _fit_dict(rows, True)


# ---------------------------------------------------------------------------------------
# Bernstein helpers (vectorised over segments: coefficient axis 1)


def _spline_knots(knots: Array | None, m: int) -> np.ndarray:
    """The ``(m + 1,)`` joint parameters of a spline of ``m`` cubics (default ``0 … m``);
    their values are checked by the core (``ph_check_spline``)."""
    if knots is None:
        return np.arange(m + 1, dtype=float)
    kn = as_float_array(knots, "knots")
    if kn.shape != (m + 1,):
        raise ValueError(f"knots: expected shape ({m + 1},), got {kn.shape}")
    return np.ascontiguousarray(kn)


class PHSpline:
    """A G¹ spline of ``m`` PH cubics with rational frames.

    Parameters
    ----------
    control_points : array_like (m, 4, 3)
        The cubics, end to end (``b₃`` of cubic ``i`` = ``b₀`` of cubic ``i + 1``).
    knots : array_like (m + 1,), optional
        Increasing parameter values of the joints in the parametrisation of the curve the
        spline approximates (used by :meth:`parameter`); default ``0, 1, …, m``.

    Every cubic must be PH (control-polygon test, tolerance 1e-7) and start where the
    previous one ends, in its end direction (G¹, within ~1.4e-6 rad); ValueError otherwise.

    The spline is parametrised by ``s ∈ [0, m]``: cubic ``⌊s⌋`` at ``v = s − ⌊s⌋`` (``s = m``
    is the end of the last cubic). :func:`fit` builds one from a curve or samples and then
    also sets :attr:`deviation` (per segment, the largest distance to the input).
    """

    deviation: Float64Array | None

    def __init__(self, control_points: Array, knots: Array | None = None) -> None:
        cp, _ = _cubics(control_points)
        kn = _spline_knots(knots, cp.shape[0])
        # no cubics, non-finite values, knots not increasing, gaps, not PH, not G¹
        _core.ph_check_spline(cp, kn, False)
        self._init(cp, kn)

    def _init(self, cp: np.ndarray, kn: np.ndarray) -> None:
        self._cp = np.array(cp, dtype=float, order="C")       # own copies, read-only
        self._cp.setflags(write=False)
        self._knots = np.array(kn, dtype=float, order="C")
        self._knots.setflags(write=False)
        #: Per segment, the largest distance to the fitted input (set by :func:`fit`).
        self.deviation: np.ndarray | None = None

    @classmethod
    def _trusted(cls, cp: np.ndarray, kn: np.ndarray) -> PHSpline:
        """A spline from cubics known to be PH (from :func:`hermite`), without the checks."""
        self = cls.__new__(cls)
        self._init(cp, kn)
        return self

    # -- geometry -----------------------------------------------------------------------
    @property
    def control_points(self) -> Float64Array:
        """``(m, 4, 3)`` control points (read-only)."""
        return self._cp

    @property
    def knots(self) -> Float64Array:
        """``(m + 1,)`` joint parameters (read-only)."""
        return self._knots

    @property
    def segments(self) -> int:
        """The number ``m`` of PH cubics; the spline parameter ``s`` runs over ``[0, m]``."""
        out: int = self._cp.shape[0]
        return out

    def __len__(self) -> int:
        return self.segments

    def __repr__(self) -> str:
        return f"PHSpline(segments={self.segments})"

    def _s(self, s: Param) -> np.ndarray:
        a = as_float_array(s, "s")
        if a.ndim > 1:
            raise ValueError(f"s: expected a scalar or a 1-D array, got shape {a.shape}")
        return np.ascontiguousarray(np.atleast_1d(a))  # values: the core (finite, in [0, m])

    def samples(self, n_per_segment: int = 16) -> Float64Array:
        """``m·n + 1`` uniformly spaced spline parameters ``s`` (the joints included)."""
        most = max(1, (MAX_SAMPLES - 1) // self.segments)
        n = as_int(n_per_segment, "n_per_segment", 1, most, out_of_bounds=lambda x: (
            f"must be at least 1 and at most {most:,} ({self.segments} cubics, at most "
            f"{MAX_SAMPLES:,} samples), got {x}"))
        return np.linspace(0.0, self.segments, self.segments * n + 1)

    def parameter(self, u: float | Array) -> Float64Array:
        """Spline parameters ``s`` of curve parameters ``u`` (linear between the knots)."""
        a = np.atleast_1d(_finite(as_float_array(u, "u"), "u"))
        k = self._knots
        if np.any((a < k[0]) | (a > k[-1])):
            raise ValueError(f"u: values must lie within [{k[0]}, {k[-1]}]")
        out: Float64Array = np.interp(a, k, np.arange(self.segments + 1, dtype=float))
        return out

    def evaluate(self, s: float | Array, derivative: int = 0) -> Float64Array:
        """Points (or derivatives with respect to the local ``v``) at ``s``, ``(n, 3)``."""
        d = as_int(derivative, "derivative", minimum=0)  # <= 3: the core
        return _core.ph_eval(self._cp, self._s(s), d)

    def points(self, n_per_segment: int = 16) -> Float64Array:
        """Points at :meth:`samples` ``(m·n + 1, 3)``."""
        return self.evaluate(self.samples(n_per_segment))

    # -- frames -------------------------------------------------------------------------
    def _initial(self, initial: Array | None) -> np.ndarray | None:
        if initial is None:
            return None
        r = as_float_array(initial, "initial")
        if r.shape != (3,):
            raise ValueError(f"initial: expected shape (3,), got {r.shape}")
        return np.ascontiguousarray(r)

    def _frames(self, s: Param, mode: str, initial: Array | None, omega_start: float
                ) -> tuple[Float64Array, Float64Array]:
        om = as_finite(omega_start, "omega_start")
        return _core.ph_frames(self._cp, self._s(s), mode, self._initial(initial), om, None)

    def frenet(self, s: float | Array) -> Float64Array:
        """Rational Frenet frames ``(n, 3, 3)``, columns ``(n, b, t)``: ``t = x′/σ``,
        ``b ∥ x′ × x″``, ``n = b × t`` (MJ (19)). Evaluated as the Euler–Rodrigues frame of the
        quaternion preimage (columns of the rotation ``A(v)/|A(v)|``), which on a PH cubic is
        the Frenet frame turned by a constant angle — well conditioned where ``x′ × x″`` is
        tiny. On straight cubics (no Frenet frame) the reference vector of :meth:`rmf` is
        used."""
        out: Float64Array = self._frames(s, "frenet", None, 0.0)[0]
        return out

    def rmf(
        self,
        s: float | Array | None = None,
        *,
        initial: Array | None = None,
        exact: bool = False,
        omega_start: float = 0.0,
        n_per_segment: int = 16,
    ) -> Float64Array:
        """Rotation-minimising frames ``(n, 3, 3)`` (columns ``r, s, t``) at ``s``.

        ``exact=True``: the RMF of the PH spline, ``r = sin Ω b + cos Ω n`` with the closed
        form ``Ω``; ``exact=False`` (default): the rational approximation ``Ω̃`` of
        :meth:`angle_fit` — the frame of :meth:`rational_frames` and :meth:`surface`, which
        equals the exact one at every joint and differs by at most ``√I_min`` in angle
        inside. The start: ``initial`` (a vector, projected onto the normal plane at
        ``s = 0``) or the angle ``omega_start`` from the principal normal towards the
        binormal of the first bent cubic (default 0: ``r = n``). Every following cubic
        starts from the exact end vector of the previous one; straight cubics carry ``r``.
        ``s`` defaults to :meth:`samples` ``(n_per_segment)``.
        """
        if s is None:
            s = self.samples(n_per_segment)
        mode = "exact" if as_bool(exact, "exact") else "rational"
        out: Float64Array = self._frames(s, mode, initial, omega_start)[0]
        return out

    def angle(
        self,
        s: float | Array,
        *,
        initial: Array | None = None,
        exact: bool = False,
        omega_start: float = 0.0,
    ) -> Float64Array:
        """The angle of :meth:`rmf`'s ``r`` at ``s``, radians from ``n`` towards ``b`` of
        the local cubic: ``Ω̃`` (rational, default) or ``Ω`` (``exact=True``). Per cubic, not
        unwrapped across joints; 0 on straight cubics."""
        mode = "exact" if as_bool(exact, "exact") else "rational"
        out: Float64Array = self._frames(s, mode, initial, omega_start)[1]
        return out

    def angle_fit(
        self, *, initial: Array | None = None, omega_start: float = 0.0
    ) -> dict[str, Any]:
        """Per-cubic data of the rational angle function (see :func:`angle_fit`; the start
        as in :meth:`rmf`). Values are ``(m,)`` arrays, ``beta``/``gamma`` ``(m, 3)``."""
        om = as_finite(omega_start, "omega_start")
        rows = _core.ph_frame_setup(self._cp, self._initial(initial), om, None)
        return _fit_dict(rows, False)

    def rational_frames(
        self, *, initial: Array | None = None, omega_start: float = 0.0
    ) -> dict[str, Float64Array]:
        """Bernstein coefficients of the rational RMF, per cubic (MJ (29), rotated pair).

        MJ write the frame with the Frenet numerators ``n̂ = σx″ − σ′x′``, ``b̂ = x′ × x″``
        (degree 2, ``|n̂| = |b̂| = 6L₂sθσ``). The same rational functions come better
        conditioned from the Euler–Rodrigues numerators ``ê₂ = A j A*``, ``ê₃ = A k A*``
        (degree 2, ``|ê| = σ = |A|²``; ``n̂ ∝ cos β ê₂ + sin β ê₃``, β = ``erf_angle``): with
        ``ψ = β + φ``, ``ê₂ψ = cos ψ ê₂ + sin ψ ê₃``, ``ê₃ψ = cos ψ ê₃ − sin ψ ê₂``,
        ``G = sg γ``, ``B = β_W`` (the denominator coefficients of :func:`angle_fit`)::

            f₂ = [2GB ê₃ψ + (B² − G²) ê₂ψ]/ω,  f₃ = [(B² − G²) ê₃ψ − 2GB ê₂ψ]/ω,
            ω = σ (B² + G²)

        i.e. ``f₂ = sin Ω̃ b + cos Ω̃ n``, ``f₃ = t × f₂``. Returns ``{"f2": (m, 7, 3),
        "f3": (m, 7, 3), "weight": (m, 7), "tangent": (m, 3, 3), "speed": (m, 3)}``:
        ``r = f2/weight``, ``s = f3/weight`` (degree 6) and ``t = tangent/speed``
        (``A i A*``/``|A|²``, degree 2). Straight cubics get constant numerators and weight 1.
        """
        fit = self.angle_fit(initial=initial, omega_start=omega_start)
        rf = _rational_numerators(fit)
        st = fit["straight"]
        if st.any():
            r = self.rmf(np.flatnonzero(st).astype(float), initial=initial,
                         omega_start=omega_start)[:, :, 0]
            _straighten(rf, st, self._cp[st], r)
        return rf

    def surface(
        self,
        section_ctrl: Array,
        section_weights: Array | None = None,
        *,
        initial: Array | None = None,
        omega_start: float = 0.0,
    ) -> Float64Array:
        """Rational Bézier sweep surface, one homogeneous patch per cubic (MJ (42), corrected).

        ``s(u, v) = x(v) + c₂(u) f₂(v) + c₃(u) f₃(v)`` with the rational frame of
        :meth:`rational_frames` and the rational cross-section ``c(u) = Σ wⱼcⱼBⱼᵐ/Σ wⱼBⱼᵐ``
        (``section_ctrl (m+1, 2)`` coordinates along ``(r, s)``, weights default 1; a polygon
        edge is ``m = 1``). In homogeneous form the numerator is
        ``x ω C₀ + C₂ F₂ + C₃ F₃`` and the weight ``ω C₀`` (degree 9 in ``v``, ``m`` in ``u``).

        Returns ``(segments, 10, m + 1, 4)``: control points ``(x·w, y·w, z·w, w)`` indexed
        ``[cubic, i (v), j (u)]``. Caveat: Bernstein weights of ``ω`` can be negative (when
        ``θ > 90°``) although ``ω > 0`` on ``[0, 1]``; NURBS exporters that need positive
        weights must subdivide or elevate.
        """
        c, wj = _section(section_ctrl, section_weights)
        rf = self.rational_frames(initial=initial, omega_start=omega_start)
        return _sweep_patches(self._cp, rf, c, wj)

    def sweep(
        self,
        profile: Array,
        *,
        n_per_segment: int = 16,
        initial: Array | None = None,
        exact: bool = False,
        omega_start: float = 0.0,
        **kwargs: Any,
    ) -> Mesh:
        """A triangle mesh of a profile swept along the spline: :func:`spinal.sweep` on the
        points :meth:`points` ``(n_per_segment)`` with the frames :meth:`rmf` (rational by
        default, the frame of :meth:`surface`). ``kwargs`` go to :func:`spinal.sweep`
        (``scale``, ``twist``, ``caps``, …). Returns a :class:`spinal.Mesh`."""
        from ._sweep import sweep as _sweep

        s = self.samples(n_per_segment)
        F = self.rmf(s, initial=initial, exact=exact, omega_start=omega_start)
        return _sweep(self.evaluate(s), profile, frames=F, **kwargs)


# ---------------------------------------------------------------------------------------
# Curve -> G¹ PH spline (Mäurer & Jüttler end of §3.2; the adaptive splitting is ours)


def fit(
    curve: Curve | Array,
    *,
    tol: float | None = None,
    segments: int | None = None,
    knots: Array | None = None,
    tangents: Array | None = None,
    domain: tuple[float, float] | None = None,
    max_segments: int = 4096,
) -> PHSpline:
    """Convert a curve into a G¹ spline of PH cubics (Mäurer & Jüttler §3.2, Theorem 10).

    Each interval ``[kᵢ, kᵢ₊₁]`` of the knots gets the PH cubic of :func:`hermite` through
    the curve's points and unit tangents at its ends; neighbouring cubics share the point
    and the tangent direction (G¹, each with its own ``v ∈ [0, 1]``). Where the curvature
    does not vanish the distance to the curve falls like ``h⁴`` with the interval length
    ``h`` (``h³`` next to an inflection at a knot); an inflection *inside* an interval can
    leave no solution.

    Parameters
    ----------
    curve : spinal.curves.Curve or array_like (n, 3)
        An analytic curve (points and exact unit tangents; knots are curve parameters) or
        samples (knots are row indices).
    tol : float, optional
        Adaptive segmentation: the largest distance allowed between each cubic and the
        input — for a curve the closest-point distance from 41 points of the cubic to the
        arc (Newton projection), for samples from the input rows inside the interval to
        the cubic. Starts from 4 uniform intervals for a curve (every ⌈n/8⌉-th row for
        samples) plus knots at the inflections (local minima of κ with κ·diag < 1e-6, or
        rows where the discrete binormal flips) and splits so that the tangent turns by
        less than π/2 on every interval; then halves intervals (middle row for samples)
        until they are within ``tol``. Default when neither ``segments`` nor ``knots`` is
        given: ``1e-5`` times the bounding-box diagonal.
    segments : int, optional
        ``segments`` uniform intervals (of the parameter, or of the row index), no
        adaptivity; at most 100,000.
    knots : array_like, optional
        Explicit increasing knots (curve parameters, or integer sample rows); the spline
        covers [knots[0], knots[-1]].
    tangents : array_like (n, 3), optional
        Tangents of the samples (default :func:`spinal.estimate_tangents`).
    domain : (float, float), optional
        Parameter interval of an analytic curve (default ``curve.domain``).
    max_segments : int
        Adaptive segmentation stops with a ValueError beyond this many cubics.

    Returns
    -------
    PHSpline
        With ``knots`` (curve parameters or rows) and ``deviation`` per cubic.

    Raises
    ------
    ValueError
        Bad input; an interval without a PH cubic (with ``segments``/``knots``: naming the
        interval and the reason — parallel end tangents, an inflection inside; with ``tol``
        only when the interval cannot be split further); ``tol`` not reachable.
    """
    from .curves import Curve

    given = [x is not None for x in (tol, segments, knots)]
    if sum(given) > 1:
        raise TypeError("tol, segments, knots: pass at most one of them")
    max_segments = as_int(max_segments, "max_segments", 1, _MAX_FIT_SEGMENTS)
    analytic = isinstance(curve, Curve)
    shape = curve if isinstance(curve, Curve) else None  # the analytic curve
    pts: np.ndarray | None = None  # the samples
    if isinstance(curve, Curve):
        if tangents is not None:
            raise TypeError("tangents: not accepted with an analytic curve (exact tangents)")
        lo, hi = curve.domain if domain is None else domain
        lo, hi = float(lo), float(hi)
        if not (np.isfinite(lo) and np.isfinite(hi) and hi > lo):
            raise ValueError(f"domain: expected a finite interval (lo, hi), got {domain!r}")
        probe = curve.point(np.linspace(lo, hi, 257))
        diag = float(np.linalg.norm(probe.max(0) - probe.min(0)))

        def data(k: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            return curve.point(k), curve.tangent(k)
    else:
        if domain is not None:
            raise TypeError("domain: only for analytic curves")
        from ._frames import estimate_tangents
        from ._validate import as_points

        pts = as_points(curve, "curve")
        _finite(pts, "curve")
        n = pts.shape[0]
        if n < 2:
            raise ValueError(f"curve: need at least 2 samples, got {n}")
        if tangents is None:
            T = estimate_tangents(pts)
        else:
            T = as_points(tangents, "tangents")
            _finite(T, "tangents")
            if T.shape[0] != n:
                raise ValueError(f"tangents: expected {n} rows like curve, got {T.shape[0]}")
            nt = np.linalg.norm(T, axis=1)
            if not np.all(nt > 0):
                raise ValueError(f"tangents: zero tangent at row {int(np.argmin(nt))}")
            T = T / nt[:, None]
        lo, hi = 0.0, float(n - 1)
        diag = float(np.linalg.norm(pts.max(0) - pts.min(0)))

        def data(k: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            i = k.astype(np.intp)
            return pts[i], T[i]

    def solve(k: np.ndarray, what: str) -> np.ndarray:
        p, t = data(k)
        cp, counts, codes = _hermite_batch(p[:-1], t[:-1], p[1:], t[1:])
        bad = np.flatnonzero(counts == 0)
        if bad.size:
            i = int(bad[0])
            raise ValueError(f"{what}: interval {i} [{k[i]:g}, {k[i + 1]:g}]: "
                             f"{_REASONS[int(codes[i])]}; split it or move the knots")
        return cp

    def deviation(cp: np.ndarray, k: np.ndarray) -> np.ndarray:
        if shape is not None:
            return _dev_curve(shape, cp, k[:-1], k[1:], lo, hi)
        assert pts is not None  # samples when not analytic
        return _dev_rows(cp, pts, k[:-1].astype(np.intp), k[1:].astype(np.intp))

    def deviation_between(cp: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        if shape is not None:
            return _dev_curve(shape, cp, a, b, lo, hi)
        assert pts is not None  # samples when not analytic
        return _dev_rows(cp, pts, a.astype(np.intp), b.astype(np.intp))

    if segments is not None or knots is not None:
        k, what = _fixed_knots(segments, knots, analytic, lo, hi)
        cp = solve(k, what)
        sp = PHSpline._trusted(cp, k)
        sp.deviation = deviation(cp, k)
        return sp

    tol = 1e-5 * diag if tol is None else as_positive(tol, "tol")
    k = _initial_knots(shape, pts, data, lo, hi, diag)
    h_min = 1e-6 * (hi - lo) if analytic else 1.0
    # work queue, processed in batches
    pending = [(k[i], k[i + 1]) for i in range(len(k) - 1)]
    done: list[tuple[float, float, np.ndarray, float]] = []
    while pending:
        a = np.array([x[0] for x in pending])
        b = np.array([x[1] for x in pending])
        pa, ta_ = data(a)
        pb, tb_ = data(b)
        cp, counts, codes = _hermite_batch(pa, ta_, pb, tb_)
        dev = np.full(a.size, np.inf)
        okr = counts > 0
        if okr.any():
            dev_ok = deviation_between(cp[okr], a[okr], b[okr])
            dev[okr] = dev_ok
        pending = []
        for j in range(a.size):
            short = (b[j] - a[j]) <= (1.0 if not analytic else h_min)
            if okr[j] and (dev[j] <= tol or (short and not analytic)):
                done.append((a[j], b[j], cp[j], dev[j]))
                continue
            if short:
                why = (_REASONS[int(codes[j])] if not okr[j] else
                       f"tolerance {tol:g} not reachable (deviation {dev[j]:.3g})")
                raise ValueError(f"tol: interval [{a[j]:g}, {b[j]:g}] cannot be split "
                                 f"further: {why}")
            m = (a[j] + b[j]) / 2 if analytic else np.floor((a[j] + b[j]) / 2)
            pending += [(a[j], m), (m, b[j])]
        if len(done) + len(pending) > max_segments:
            raise ValueError(f"max_segments: more than {max_segments} cubics needed for "
                             f"tol = {tol:g}")
    done.sort(key=lambda x: x[0])
    kn = np.array([x[0] for x in done] + [done[-1][1]])
    sp = PHSpline._trusted(np.stack([x[2] for x in done]), kn)
    sp.deviation = np.array([x[3] for x in done])
    return sp
