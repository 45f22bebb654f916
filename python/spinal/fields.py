"""Divergence-free velocity fields for volume-preserving deformation (issue 4).

A field is a small immutable object describing a closed-form velocity field ``v(X, t)`` with
``div v = 0`` exactly; evaluate it with ``field(points, t=0.0) -> (n, 3)``, add fields with
``+`` or :func:`sum`, and move points along it with :func:`spinal.advect`. Everything is
float64 and evaluated in Rust (in parallel) at the points themselves: no grid sampling.

Units: lengths in the mesh's units, time in the caller's units; a velocity is length/time,
an angular speed rad/time (right-handed about the axis), a twist rate rad/(length·time), a
bend rate rad/(length²·time).

**Curl fields** (Zheng's thesis Ch. 12, signs and scales corrected as in the issue-4 brief,
errata A-16/A-17): ``V = c·curl(φ(d) B)`` with ``d`` the signed distance to a spherical tool,
``φ = (R − |d|)^p`` zero beyond the reach ``R`` (``p = 2`` as in the thesis: the field is C⁰
at ``|d| = R``; ``falloff_power=4`` makes it C²):

* :func:`translation` — ``V = (e^{p−1}/R^p)[e u + (p/2) sgn(d)((n·u)Y − (n·Y)u)]``,
  ``e = R − |d|``: on the tool surface the normal velocity is exactly ``u·n``;
* :func:`rotation` — ``V = (e^{p−1}/(3R^p))[p sgn(d) n × (|Y|²Ω − (Ω·Y)Y) + 3e Ω × Y]``;
* :func:`twist`, :func:`bend` — swirls ``v = h(z, r) a × Y`` about an axis, ``h = κ z W(r)``
  and ``β r² W(r)`` with ``W = (1 − r/R)²`` (or the thesis's curl form).

**Cross-product fields** ``v = ∇p × ∇q`` (von Funck et al. 2006, thesis Ch. 11) with the
region function ``D = b(clamp(d/R_f, 0, 1))``, ``b = 4σ³ − 3σ⁴`` (C¹) or ``σ`` (linear):

* :func:`sphere`, :func:`capsule` (the exact distance-field extension to a free-form tool)
  — ``v = (1 − D)² u + (1 − D)D′[(n·u)Y − (n·Y)u]``, rigid inside the tool;
* :func:`strip` — along the axis (type I) or across it (type II);
* :func:`strip_curve` — type I along a curved axis (the C² spline through samples):
  ``v = s (1 − D)(1 − D − r D′) T``, ``r`` the distance to the axis, ``T`` its tangent at the
  closest point;
* :func:`torus` — a torus moving along its axis;
* :func:`sdf_tool`, :func:`mesh_tool` — a free-form tool given by a sampled signed distance
  (or a closed triangle mesh): the sphere field with the tool's distance ``d``, interpolated
  by a C² tricubic B-spline whose exact gradient gives ``n = ∇d``.

**Tools along a path** — :func:`along_path`: a sphere tool travels along a spine curve at
constant speed, posed by Hermite positions and the interpolated rotation-minimizing frames
of :func:`spinal.frames`; it translates (pushes or carries), and optionally rotates with the
frames, twists or bends the material around it.
"""

from __future__ import annotations

import numbers
from collections.abc import Iterable

import numpy as np

from . import _core
from ._validate import as_choice, as_float_array, as_points

__all__ = [
    "Field",
    "along_path",
    "bend",
    "capsule",
    "mesh_tool",
    "rotation",
    "sdf_tool",
    "sphere",
    "strip",
    "strip_curve",
    "sum",
    "torus",
    "translation",
    "twist",
]

ROW = 16


class Field:
    """A divergence-free velocity field: a sum of elements (see the module docstring).

    Build fields with the constructors of :mod:`spinal.fields`; they are immutable.

    ``field(points, t=0.0)`` returns the ``(n, 3)`` velocities at time ``t`` (tools that move
    are at ``center + velocity·t``). ``f + g`` is the sum field. ``max_speed`` is a bound of
    ``|v|`` used by the step rule, ``length_scale`` the smallest reach (the length over which
    the field changes), ``steps(duration)`` the number of RK4 steps that
    :func:`spinal.advect` takes when ``steps=None``.
    """

    __slots__ = ("_names", "_rows")

    def __init__(self, rows: np.ndarray, names: tuple[str, ...]):
        rows = np.array(rows, dtype=np.float64, copy=True).reshape(-1, ROW)
        rows.flags.writeable = False
        _core.field_info(rows, 1.0)  # validates every row
        self._rows = rows
        self._names = names

    @property
    def rows(self) -> np.ndarray:
        """The elements as read-only rows of 16 floats (the layout of ``spinal._core``)."""
        return self._rows

    def __call__(self, points, t: float = 0.0) -> np.ndarray:
        x = as_points(points, "points")
        _check_finite(x, "points")
        return _core.field_eval(x, self._rows, _real(t, "t"))

    def __add__(self, other: Field) -> Field:
        if not isinstance(other, Field):
            return NotImplemented
        return Field(np.vstack([self._rows, other._rows]), self._names + other._names)

    def __radd__(self, other):
        if isinstance(other, numbers.Number) and other == 0:  # builtin sum()
            return self
        return NotImplemented

    def __len__(self) -> int:
        return len(self._rows)

    def breakpoints(self) -> np.ndarray:
        """Times at which a path tool (:func:`along_path`) passes a spine sample, sorted: its
        velocity is only continuous there, so :func:`spinal.advect` ends steps at them."""
        r = self._rows
        out = []
        for i in np.flatnonzero(r[:, 0] == 7):
            t0, dur, n = r[i, 1], r[i, 2], int(r[i, 11])
            s = r[i + 1: i + 1 + n, 13]
            out.append(t0 + dur * (s - s[0]) / (s[-1] - s[0]))
        return np.unique(np.concatenate(out)) if out else np.zeros(0)

    @property
    def max_speed(self) -> float:
        """A bound of the speed ``|v|`` (length/time): the sum over the elements of each
        element's bound (closed form where one exists, else a maximum sampled over its
        support); ``0`` for the zero field. Used by :meth:`steps`."""
        return _core.field_info(self._rows, 1.0)[0]

    @property
    def length_scale(self) -> float:
        """The smallest length over which an element's field falls from its tool value to zero
        (length): its ``reach`` (for :func:`twist` and :func:`bend`, their ``radius``), the
        minimum over the elements; ``inf`` for the zero field. Used by :meth:`steps`."""
        return _core.field_info(self._rows, 1.0)[1]

    def steps(self, duration: float) -> int:
        """Default step count: ``max(4, ⌈|duration|·8·max_speed/length_scale⌉)`` (a step moves
        a point by at most 1/8 of the length scale)."""
        return _core.field_info(self._rows, _real(duration, "duration"))[2]

    def __repr__(self) -> str:
        return f"spinal.fields.Field({' + '.join(self._names) or 'zero'})"


def _check_finite(x: np.ndarray, name: str) -> None:
    bad = ~np.isfinite(x).all(axis=-1)
    if bad.any():
        raise ValueError(f"{name}: row {int(np.argmax(bad))} is not finite (NaN or inf)")


def _real(x, name: str) -> float:
    if isinstance(x, bool) or not isinstance(x, numbers.Real):
        if isinstance(x, np.ndarray) and x.shape == () and x.dtype.kind in "iuf":
            x = x.item()
        else:
            raise TypeError(f"{name}: expected a real number, got {type(x).__name__}")
    x = float(x)
    if not np.isfinite(x):
        raise ValueError(f"{name}: must be finite, got {x}")
    return x


def _positive(x, name: str) -> float:
    x = _real(x, name)
    if not x > 0:
        raise ValueError(f"{name}: must be positive, got {x}")
    return x


def _vec3(x, name: str) -> np.ndarray:
    a = as_float_array(x, name)
    if a.shape != (3,):
        raise ValueError(f"{name}: expected 3 numbers, got shape {a.shape}")
    if not np.isfinite(a).all():
        raise ValueError(f"{name}: must be finite, got {a}")
    return a


def _axis(x, name: str = "axis") -> np.ndarray:
    a = _vec3(x, name)
    n = np.linalg.norm(a)
    if not n > 0:
        raise ValueError(f"{name}: must be a non-zero vector")
    return a / n


def _power(x) -> int:
    if isinstance(x, bool) or not isinstance(x, numbers.Integral) or int(x) not in (2, 3, 4):
        raise ValueError(f"falloff_power: must be 2, 3 or 4, got {x!r}")
    return int(x)


def _blend(x) -> float:
    return 1.0 if as_choice(x, "blend", ("c1", "linear")) == "linear" else 0.0


def _spine_points(points) -> tuple[np.ndarray, np.ndarray]:
    """A tool's axis or path, ``(n, 3)`` finite with ``n ≥ 2`` and no repeated consecutive
    samples, and its chord lengths."""
    x = as_points(points, "points")
    _check_finite(x, "points")
    if len(x) < 2:
        raise ValueError(f"points: need at least 2 samples, got {len(x)}")
    chords = np.linalg.norm(np.diff(x, axis=0), axis=1)
    if not (chords > 0).all():
        i = int(np.argmin(chords))
        raise ValueError(f"points: consecutive samples {i} and {i + 1} coincide")
    return x, chords


def _row(*parts) -> np.ndarray:
    r = np.zeros(ROW)
    flat = np.concatenate([np.atleast_1d(np.asarray(p, dtype=np.float64)) for p in parts])
    r[: len(flat)] = flat
    return r


def translation(center, radius, velocity, *, reach=None, falloff_power: int = 2,
                moving: bool = True) -> Field:
    """A spherical tool moving with constant ``velocity``, pushing the material around it.

    Curl field (thesis eq. 12.1–12.2, corrected sign and scale)::

        V = (e^{p−1}/R^p) [ e u + (p/2) sgn(d) ((n·u) Y − (n·Y) u) ]   for |d| < R, else 0

    with ``Y = X − c(t)``, ``c(t) = center + velocity·t`` (``moving=False``: the tool stays at
    ``center``), ``d = |Y| − radius``, ``n = Y/|Y|``, ``e = R − |d|``, ``R = reach``
    (default: ``radius``, which keeps a 40k-vertex icosphere's volume error below 1e-4; the
    spec's 0.5·radius does not). On the tool surface the normal velocity equals ``u·n``:
    material neither enters the tool nor separates from it.

    Parameters
    ----------
    center : (3,) tool centre at t = 0.
    radius : tool radius ρ > 0.
    velocity : (3,) tool velocity (length/time); zero gives the zero field.
    reach : R > 0, width of the region around the tool that moves.
    falloff_power : p in {2, 3, 4}; 2 is the thesis's ``(R − |d|)²`` (C⁰ at ``|d| = R``).
    """
    c, u = _vec3(center, "center"), _vec3(velocity, "velocity")
    rho = _positive(radius, "radius")
    reach = rho if reach is None else _positive(reach, "reach")
    return Field(_row(0, c, u, rho, reach, _power(falloff_power), float(bool(moving))),
                 ("translation",))


def rotation(center, radius, axis, angular_speed, *, pivot=None, reach=None,
             falloff_power: int = 2) -> Field:
    """A spherical tool turning at ``angular_speed`` (rad/time, right-handed) about ``axis``
    through ``pivot`` (default: its centre, a tool spinning in place).

    Curl field (thesis eq. 12.3, corrected scale), with ``Y = X − pivot``, ``Ω = ω a`` and
    ``d``, ``n`` measured from the tool (whose centre orbits the pivot when off it)::

        V = (e^{p−1}/(3R^p)) [ p sgn(d) n × (|Y|²Ω − (Ω·Y)Y) + 3 e Ω × Y ]

    On the tool surface the normal velocity equals ``(Ω × Y)·n``. A tool centred on the pivot
    gives a pure swirl ``h(r) a × Y`` (zero normal velocity, an exact rotation on every
    sphere about the pivot).
    """
    c = _vec3(center, "center")
    rho = _positive(radius, "radius")
    a = _axis(axis)
    w = _real(angular_speed, "angular_speed")
    o = c if pivot is None else _vec3(pivot, "pivot")
    reach = rho if reach is None else _positive(reach, "reach")
    return Field(_row(1, c, o, w * a, rho, reach, _power(falloff_power)), ("rotation",))


def _swirl(center, axis, rate, radius, form, bend: bool) -> Field:
    o = _vec3(center, "center")
    a = _axis(axis)
    k = _real(rate, "rate")
    r = _positive(radius, "radius")
    curl = as_choice(form, "form", ("rate", "curl")) == "curl"
    return Field(_row(2, o, a, k, r, float(bend), float(curl)), ("bend" if bend else "twist",))


def twist(center, axis, rate, radius, *, form: str = "rate") -> Field:
    """Twist about ``axis`` through ``center``: angle rate ``κ z`` (rad/time) at height
    ``z = a·(X − center)``, fading to 0 at distance ``radius`` from the centre.

    ``form="rate"``: ``v = κ z (1 − r/R)² a × Y`` (no counter-rotation);
    ``form="curl"``: the thesis's ``−(κ/(4R²)) curl((R − r)² z (Y × a) × Y)`` =
    ``κ z (1 − r/R)(1 − 3r/(2R)) a × Y`` (turns backwards for ``r > 2R/3``).
    Every sphere about the centre turns rigidly: the exact flow is a rotation by ``h·t``.
    """
    return _swirl(center, axis, rate, radius, form, False)


def bend(center, axis, rate, radius, *, form: str = "rate") -> Field:
    """The thesis's "bend" (eq. 12.6, a differential swirl): angle rate ``β r²`` about
    ``axis`` through ``center``, ``r = |X − center|``, fading to 0 at ``radius``.

    ``form="rate"``: ``v = β r² (1 − r/R)² a × Y``; ``form="curl"``:
    ``−(β/(5R²)) curl((R − r)² r² (Y × a) × Y)`` = ``β r² (1 − r/R)(1 − 7r/(5R)) a × Y``.
    A rod through the centre (perpendicular to the axis) winds into a spiral.
    """
    return _swirl(center, axis, rate, radius, form, True)


def sphere(center, radius, velocity, *, reach=None, blend: str = "c1",
           moving: bool = True) -> Field:
    """von Funck's region translation around a sphere (``r_i = radius``,
    ``r_o = radius + reach``): ``v = ∇p × ∇q`` with ``p = (1 − D) N·Y``, ``q = (1 − D) B·Y``::

        v = (1 − D)² u + (1 − D) D′ [ (n·u) Y − (n·Y) u ]

    rigid (``v = u``) inside the sphere, zero beyond ``radius + reach``.
    """
    c, u = _vec3(center, "center"), _vec3(velocity, "velocity")
    rho = _positive(radius, "radius")
    reach = rho if reach is None else _positive(reach, "reach")
    return Field(_row(3, c, u, rho, reach, _blend(blend), float(bool(moving))), ("sphere",))


def capsule(start, end, radius, velocity, *, reach=None, blend: str = "c1",
            moving: bool = True) -> Field:
    """Region translation around a capsule (segment ``start``–``end``, ``radius``): the exact
    distance-field extension of :func:`sphere` to a free-form tool, ``Y = X − midpoint``,
    ``d`` the capsule's signed distance, ``n = ∇d``. Divergence-free for any C¹ distance.
    """
    a, b = _vec3(start, "start"), _vec3(end, "end")
    u = _vec3(velocity, "velocity")
    rho = _positive(radius, "radius")
    reach = rho if reach is None else _positive(reach, "reach")
    return Field(_row(4, a, b, u, rho, reach, _blend(blend), float(bool(moving))), ("capsule",))


def strip(start, end, radius, velocity, *, kind: str = "along", reach=None,
          blend: str = "c1") -> Field:
    """A straight strip (a capsule from ``start`` to ``end``) moving the material around it
    (thesis §11.2.2–11.2.3, naming per erratum A-14).

    ``kind="along"`` (type I, "sticking"): ``velocity`` parallel to the axis; the material
    around slides along the strip (the :func:`capsule` field, static).
    ``kind="across"`` (type II, "sweeping"): ``velocity`` perpendicular to the axis;
    ``p = s σ(X)`` (arc length of the closest axis point), ``q = (1 − D) U·(X − start)``,
    ``U = m̂ × t``; the field is zero beyond the end planes (a tangential jump only).
    For a curved axis (type I) see :func:`strip_curve`.
    """
    a, b = _vec3(start, "start"), _vec3(end, "end")
    u = _vec3(velocity, "velocity")
    rho = _positive(radius, "radius")
    reach = rho if reach is None else _positive(reach, "reach")
    kind = as_choice(kind, "kind", ("along", "across"))
    length = np.linalg.norm(b - a)
    if not length > 0:
        raise ValueError("end: must differ from start")
    t = (b - a) / length
    s = np.linalg.norm(u)
    along = float(u @ t)
    if kind == "along":
        if abs(abs(along) - s) > 1e-9 * s:
            raise ValueError("velocity: must be parallel to the strip axis for kind='along'")
        return Field(_row(4, a, b, u, rho, reach, _blend(blend), 0.0), ("strip(along)",))
    if abs(along) > 1e-9 * s:
        raise ValueError("velocity: must be perpendicular to the strip axis for kind='across'")
    return Field(_row(6, a, b, u, rho, reach, _blend(blend)), ("strip(across)",))


def torus(center, axis, major, minor, speed, *, reach=None, blend: str = "c1",
          moving: bool = True) -> Field:
    """A torus (major radius ``major``, tube radius ``minor``) moving along its ``axis`` with
    ``speed`` (thesis §11.2.4; the two half-torus fields summed in closed form)::

        v = s (R_t/ρ) [ (1 − D) k + D′ (ρ − R_t) e_θ × n ]

    with ``ρ`` the distance to the axis. Needs ``minor + reach < major``.
    """
    c, k = _vec3(center, "center"), _axis(axis)
    big, small = _positive(major, "major"), _positive(minor, "minor")
    s = _real(speed, "speed")
    reach = small if reach is None else _positive(reach, "reach")
    if not small + reach < big:
        raise ValueError(f"minor: minor + reach ({small + reach}) must be below major ({big})")
    return Field(_row(5, c, k, s, big, small, reach, _blend(blend), float(bool(moving))),
                 ("torus",))


def strip_curve(points, radius, speed, *, reach=None, blend: str = "c1") -> Field:
    """A strip of type I along a curved axis (thesis §11.2.2, "sticking"; A-14): the material
    within ``radius`` of the axis flows along it at ``speed`` (length/time, from
    ``points[0]`` towards ``points[-1]``; negative: backwards), leaves at the head, comes back
    outside (within ``radius + reach``) and re-enters at the tail. Static (the strip does not
    move); :func:`strip` with ``kind="along"`` is the straight special case.

    **Axis.** The clamped C² cubic spline ``γ`` through ``points`` in cumulative chord length
    ``S``, with the unit end tangents of :func:`spinal.estimate_tangents` (the tangents of
    :func:`spinal.frames`) as end derivatives. ``c(X) = γ(s(X))`` is the closest point of the
    spline (``(X − γ)·γ′ = 0``), ``r = |X − c(X)|``, ``T = γ′/|γ′|`` at ``s(X)``.

    **Field** (thesis: ``p = (1 − D) N·(X − c(X))``, ``q = (1 − D) B·(X − c(X))`` with ``(N, B)``
    the rotation-minimizing frame, ``v = ∇p × ∇q``). In tube coordinates ``X = γ + aN + bB``
    an RMF gives ``∇a = N``, ``∇b = B`` exactly (it does not turn about ``T``), hence::

        v = speed · (1 − D)(1 − D − r D′) · T(s(X))          D = b(clamp((r − ρ)/R_f, 0, 1))

    the same for every RMF (they differ by a constant turn), so no frame is stored; beyond the
    end planes the foot point is the end sample and ``v`` is :func:`sphere`'s field about it
    with velocity ``speed·T_end`` (continuous across the end planes). Exactly divergence-free:
    ``div(J(r) T) = J′ ∇r·T + J T′·∇s = 0`` (``∇r ⟂ T``, ``∇s ∥ T ⟂ T′``). Inside the tube
    ``v = speed·T``; the flux through each cross-section is zero. ``tests/test_deform_tools.py``
    checks it against ``∇p × ∇q`` built from double-reflection frames by finite differences.

    Parameters
    ----------
    points : (n, 3) axis samples, n ≥ 2, no repeated consecutive points.
    radius : ρ > 0, the tube that flows rigidly along the axis.
    speed : flow speed inside the tube.
    reach : R_f > 0, width of the return-flow region (default ``radius``).
    blend : "c1" (``4σ³ − 3σ⁴``, v continuous) or "linear".

    The closest point must be unique within ``radius + reach``: the axis may not bend with
    curvature ``κ`` such that ``κ·(radius + reach + segment length) ≥ 1``, nor come back within
    ``2(radius + reach)`` of itself (between parts more than ``π(radius + reach)`` apart
    along it); both raise ``ValueError`` naming ``points``. Both are checked on 16 points per
    segment (the second on a uniform grid of cells of size ``2(radius + reach)``, a cost about
    linear in the number of samples).
    """
    from ._frames import estimate_tangents

    x, chords = _spine_points(points)
    rho = _positive(radius, "radius")
    sp = _real(speed, "speed")
    reach = rho if reach is None else _positive(reach, "reach")
    lin = _blend(blend)
    s = np.concatenate([[0.0], np.cumsum(chords)])
    tan = estimate_tangents(x)
    # the clamped spline's slopes (tridiagonal solve) and the axis checks, in the core
    m = _core.strip_axis(x, s, tuple(tan[0]), tuple(tan[-1]), rho, reach)
    head = _row(9, sp, rho, reach, lin, len(x))
    body = np.zeros((len(x), ROW))
    body[:, 0] = 10
    body[:, 1:4] = x
    body[:, 4:7] = m
    body[:, 7] = s
    return Field(np.vstack([head, body]), ("strip_curve",))


def _spline_prefilter(values: np.ndarray) -> np.ndarray:
    """Coefficients (n + 2 per axis, one ghost layer each side) of the natural cubic B-spline
    interpolating ``values`` on a unit grid: per axis ``c_0 = d_0``, ``c_{n−1} = d_{n−1}``,
    ``c_{i−1} + 4c_i + c_{i+1} = 6d_i`` inside, ghosts ``c_{−1} = 2c_0 − c_1`` (zero second
    derivative at the end nodes)."""
    c = values
    for axis in range(3):
        a = np.moveaxis(c, axis, 0)
        n = a.shape[0]
        out = np.empty((n + 2,) + a.shape[1:])
        out[1], out[n] = a[0], a[-1]
        rhs = 6 * a[1:-1].copy()
        rhs[0] -= a[0]
        rhs[-1] -= a[-1]
        k = n - 2
        cp = np.zeros(k)
        cp[0] = 0.25
        rhs[0] *= 0.25
        for i in range(1, k):
            w = 4 - cp[i - 1]
            cp[i] = 1 / w
            rhs[i] = (rhs[i] - rhs[i - 1]) / w
        for i in range(k - 2, -1, -1):
            rhs[i] -= cp[i] * rhs[i + 1]
        out[2:n] = rhs
        out[0] = 2 * out[1] - out[2]
        out[n + 1] = 2 * out[n] - out[n - 1]
        c = np.moveaxis(out, 0, axis)
    return c


def _cell_min(c: np.ndarray) -> np.ndarray:
    """Smallest coefficient of each cell's 4×4×4 stencil (a lower bound of the spline)."""
    for axis in range(3):
        a = np.moveaxis(c, axis, 0)
        a = np.minimum(np.minimum(a[:-3], a[1:-2]), np.minimum(a[2:-1], a[3:]))
        c = np.moveaxis(a, 0, axis)
    return c


MIN_CELLS_PER_REACH = 4


def _grid_field(values, origin, h, velocity, center, reach, blend, moving, name, what):
    u = _vec3(velocity, "velocity")
    if not (values <= 0).any():
        raise ValueError("grid: no node is inside the tool (all distances are positive)")
    if center is None:
        # volume-fraction weights of the nodes' cells, clamp(1/2 − d/h, 0, 1)
        w = np.clip(0.5 - values / h, 0.0, 1.0)
        idx = np.argwhere(w > 0)
        ww = w[w > 0]
        c = origin + (idx * ww[:, None]).sum(axis=0) / ww.sum() * h
    else:
        c = _vec3(center, "center")
    if reach is None:
        idx = np.argwhere(values <= 0)
        nodes = origin + idx * h
        reach = float((np.linalg.norm(nodes - c, axis=1) - values[values <= 0]).max())
    else:
        reach = _positive(reach, "reach")
    if not reach >= MIN_CELLS_PER_REACH * h:
        raise ValueError(
            f"{what}: grid too coarse: spacing {h:.4g} must be at most reach/"
            f"{MIN_CELLS_PER_REACH} = {reach / MIN_CELLS_PER_REACH:.4g} (the blend region needs "
            f"{MIN_CELLS_PER_REACH} cells)")
    coef = _spline_prefilter(values)
    cm = _cell_min(coef)
    edge = np.ones(cm.shape, dtype=bool)
    edge[1:-1, 1:-1, 1:-1] = False
    if (cm[edge] < reach).any():
        raise ValueError(
            "grid: the field's support (distance < reach) reaches the edge of the grid; pad "
            "the grid so that the distance is ≥ reach on its outer cells")
    flags = _blend(blend) + 2.0 * float(bool(moving))
    head = _row(11, origin, h, values.shape, u, reach, flags, c)
    flat = coef.ravel()
    k = -(-len(flat) // (ROW - 1))
    body = np.zeros((k, ROW))
    body[:, 0] = 12
    body[:, 1:] = np.concatenate([flat, np.zeros(k * (ROW - 1) - len(flat))]).reshape(k, -1)
    return Field(np.vstack([head, body]), (name,))


def sdf_tool(grid, origin, spacing, velocity, *, center=None, reach=None, blend: str = "c1",
             moving: bool = True) -> Field:
    """A free-form tool given by its signed distance sampled on a grid, translating with
    ``velocity``: Zheng's extended spherical field with the object's distance (thesis §11.2.1;
    the distance-field extension of :func:`sphere`)::

        p = (1 − D(d)) N·Y,  q = (1 − D(d)) B·Y,  Y = X − C,  N × B = u/|u|
        v = ∇p × ∇q = (1 − D)² u + (1 − D) D′ [ (∇d·u) Y − (∇d·Y) u ]

    with ``D = b(clamp(d/R_f, 0, 1))``: the material inside the tool (``d ≤ 0``) moves rigidly
    with ``u``, the field vanishes where ``d ≥ reach``. ``d`` is the C² tricubic B-spline
    interpolating the samples (natural end conditions) and ``∇d`` its exact gradient, so ``v``
    is exactly divergence-free for the interpolated distance (``∇p × ∇q`` of C² scalars); the
    sampling only decides which divergence-free field it is. Evaluated in Rust
    (``src/deform/grid.rs``); cells whose B-spline coefficients are all ``≥ reach`` are
    skipped (the basis is a partition of unity, so ``d ≥ reach`` there).

    A sphere's sampled distance reproduces :func:`sphere` with a 3rd-order error in the grid
    spacing (measured in ``tests/test_deform_tools.py``).

    Parameters
    ----------
    grid : (nx, ny, nz) signed distances (negative inside the tool, length units) at the
        nodes ``origin + (i, j, k)·spacing``; at least 8 nodes per axis, finite.
    origin : (3,) position of node (0, 0, 0).
    spacing : node spacing h > 0 (cubic cells); must be at most ``reach/4``.
    velocity : (3,) tool velocity (length/time).
    center : (3,) the tool's centre C (default: the centroid of the inside, the nodes weighted
        by the volume fraction ``clamp(1/2 − d/h, 0, 1)`` of their cells).
    reach : R_f > 0 (default: the tool's bounding radius about C estimated from the samples,
        ``max(|x_i − C| − d_i)`` over the nodes inside; exact for a sphere).
    blend : "c1" or "linear".
    moving : the tool (grid and centre) moves, ``d(X − u t)``; False keeps it at rest.

    The distance must be at least ``reach`` on the grid's outer cells (the support may not
    reach the grid's edge): ``ValueError`` naming ``grid`` otherwise.
    """
    a = as_float_array(grid, "grid")
    if a.ndim != 3 or min(a.shape) < 8:
        raise ValueError(f"grid: expected a 3-D array with at least 8 nodes per axis, got "
                         f"shape {a.shape}")
    if not np.isfinite(a).all():
        i = tuple(int(v) for v in np.argwhere(~np.isfinite(a))[0])
        raise ValueError(f"grid: value at node {i} is not finite")
    if a.size > 300**3:
        raise ValueError(f"grid: {a.size} nodes is too many (at most 300³)")
    o = _vec3(origin, "origin")
    h = _positive(spacing, "spacing")
    return _grid_field(np.array(a, dtype=np.float64), o, h, velocity, center, reach, blend,
                       moving, "sdf_tool", "spacing")


def _closed_mesh(mesh):
    from ._deform import _edges, _mesh_arrays

    V, F = _mesh_arrays(mesh)
    if not len(F):
        raise ValueError("mesh: has no faces")
    # every undirected edge, in the order of the slots 0→1 of all faces, then 1→2, then 2→0
    uniq, slot = _edges(F)
    ids = slot.T.ravel()
    cnt = np.bincount(ids, minlength=len(uniq))[ids]
    if (cnt != 2).any():
        k = np.argmax(cnt != 2)
        e = uniq[ids[k]]
        raise ValueError(f"mesh: not watertight: edge ({e[0]}, {e[1]}) belongs to {cnt[k]} "
                         f"faces (a closed tool needs exactly 2)")
    directed = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    _, dcnt = np.unique(directed, axis=0, return_counts=True)
    if (dcnt != 1).any():
        raise ValueError("mesh: faces are not consistently oriented")
    # about the mean vertex, as `Mesh.volume`, so that a small tool far away keeps its digits
    mean = V.mean(axis=0)
    c0 = V - mean
    a, b, c = c0[F[:, 0]], c0[F[:, 1]], c0[F[:, 2]]
    six = np.einsum("ij,ij->i", a, np.cross(b, c))
    vol = six.sum() / 6
    if not vol > 0:
        raise ValueError(f"mesh: encloses a non-positive volume ({vol:.4g}); faces must be "
                         f"oriented outwards")
    centroid = mean + (six[:, None] * (a + b + c)).sum(axis=0) / (24 * vol)
    return V, F, centroid


def mesh_tool(mesh, velocity, *, reach=None, resolution: int = 64, center=None,
              blend: str = "c1", moving: bool = True) -> Field:
    """A free-form tool given as a closed triangle mesh, translating with ``velocity``: the
    field of :func:`sdf_tool` with the mesh's signed distance sampled on a grid.

    The grid covers the mesh's bounding box padded by ``reach + 4·spacing`` on every side,
    with ``resolution`` nodes along its longest side; the distances come from
    ``igl.signed_distance`` (libigl, pseudonormal sign; needs ``pip install libigl``), the
    interpolation and evaluation from :func:`sdf_tool`.

    Parameters
    ----------
    mesh : a spinal.Mesh, a trimesh.Trimesh or ``(vertices, faces)``: watertight, consistently
        oriented outwards (else ``ValueError`` naming ``mesh``).
    velocity : (3,) tool velocity.
    reach : R_f > 0 (default: the bounding radius ``max |v_i − C|``, so a sphere mesh of
        radius ρ gives :func:`sphere`'s default ``reach = ρ``).
    resolution : nodes along the longest side, 16 … 256; the spacing must come out at most
        ``reach/4`` (``ValueError`` naming ``resolution`` otherwise).
    center : (3,) the tool's centre C (default: the centroid of the enclosed volume).
    blend, moving : as for :func:`sdf_tool`.
    """
    V, F, centroid = _closed_mesh(mesh)
    c = centroid if center is None else _vec3(center, "center")
    rf = float(np.linalg.norm(V - c, axis=1).max()) if reach is None else _positive(reach,
                                                                                  "reach")
    res = resolution
    if isinstance(res, bool) or not isinstance(res, numbers.Integral):
        raise TypeError(f"resolution: expected an integer, got {type(res).__name__}")
    if not 16 <= res <= 256:
        raise ValueError(f"resolution: must be in 16 … 256, got {res}")
    pad = 4
    lo, hi = V.min(axis=0), V.max(axis=0)
    h = float((hi - lo).max() + 2 * rf) / (res - 1 - 2 * pad)
    if not rf >= MIN_CELLS_PER_REACH * h:
        need = int(np.ceil(((hi - lo).max() + 2 * rf) / (rf / MIN_CELLS_PER_REACH))) + 2 * pad + 1
        raise ValueError(
            f"resolution: grid too coarse: spacing {h:.4g} must be at most reach/"
            f"{MIN_CELLS_PER_REACH} = {rf / MIN_CELLS_PER_REACH:.4g}; use resolution ≥ {need}")
    try:
        import igl
    except ImportError as e:  # pragma: no cover - libigl is a test dependency
        raise ImportError("mesh_tool: building the distance grid needs libigl (pip install "
                          "libigl); or sample the distance yourself and use "
                          "fields.sdf_tool") from e
    origin = lo - rf - pad * h
    shape = np.ceil((hi - lo + 2 * (rf + pad * h)) / h).astype(int) + 1
    axes = [origin[i] + h * np.arange(shape[i]) for i in range(3)]
    P = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    d = igl.signed_distance(P, V, F, sign_type=igl.SIGNED_DISTANCE_TYPE_PSEUDONORMAL)[0]
    return _grid_field(np.ascontiguousarray(d.reshape(tuple(shape))), origin, h, velocity, c,
                       rf, blend, moving, "mesh_tool", "resolution")


def sum(fields: Iterable[Field]) -> Field:
    """The sum of fields (still divergence-free; velocities add where supports overlap)."""
    fields = list(fields)
    for i, f in enumerate(fields):
        if not isinstance(f, Field):
            raise TypeError(f"fields: item {i} is a {type(f).__name__}, not a spinal.fields.Field")
    if not fields:
        return Field(np.zeros((0, ROW)), ())
    return Field(np.vstack([f.rows for f in fields]), tuple(n for f in fields for n in f._names))


def along_path(points, radius, duration, *, kind: str = "translate", tool: str = "push",
               rate=0.0, frames=None, t0=0.0, reach=None, falloff_power: int = 2,
               blend: str = "c1") -> Field:
    """A spherical tool travelling along a spine from ``points[0]`` (at time ``t0``) to
    ``points[-1]`` (at ``t0 + duration``) at constant speed ``u = L/duration`` in chord
    length ``L``, deforming the material around it; at rest (zero field) outside that time.

    Pose (issue-4 brief §4): in segment ``k``, ``λ = (σ − S_k)/ΔS_k`` with ``S_k`` the
    cumulative chord lengths and ``σ = u (t − t0)``,

    * centre ``o(σ)``: cubic Hermite through ``x_k, x_{k+1}`` with tangents ``t_k ΔS_k,
      t_{k+1} ΔS_k`` (exactly linear on a straight spine), velocity ``ȯ = u do/dσ``;
    * frame ``Q(σ) = F_k Exp(λ Θ_k)``, ``Θ_k = Log(F_kᵀ F_{k+1})``, ``F_k = [r_k s_k t_k]``
      the rotation-minimizing frames (``frames``, default :func:`spinal.frames` of the
      points), world angular velocity ``ω = u F_k Θ_k/ΔS_k``.

    The field at time ``t`` is a sum of divergence-free fields frozen at the pose:

    * ``tool="push"``: the curl :func:`translation` tool at ``o`` with velocity ``ȯ`` (a solid
      sphere pushing the material; normal velocity ``ȯ·n`` on its surface), or
      ``tool="carry"``: the :func:`sphere` region translation (the material inside the sphere
      moves rigidly with ``ȯ``, a point at the centre follows the path);
    * ``kind="rotate"`` adds the curl :func:`rotation` with ``Ω = ω`` about ``o`` (the region
      turns with the frames); ``kind="twist"`` adds a :func:`twist` about the moving tangent
      ``t`` with ``rate`` κ (rad/(length·time)); ``kind="bend"`` a :func:`bend` about the
      moving reference vector ``r`` with ``rate`` β (rad/(length²·time)); both swirls have
      the ball support ``radius + reach`` about ``o``.

    The velocity of the pose jumps in its derivative at the sample times
    (:meth:`Field.breakpoints`): :func:`spinal.advect` ends steps there to keep RK4 4th order.

    Parameters
    ----------
    points : (n, 3) spine samples, n ≥ 2, no repeated consecutive points.
    radius : tool radius ρ > 0.
    duration : time to travel the whole spine, > 0.
    kind : "translate", "rotate", "twist" or "bend".
    tool : "push" (curl tool) or "carry" (region translation).
    rate : twist or bend rate for ``kind="twist"``/``"bend"``.
    frames : (n, 3, 3) rotation matrices with columns ``(r, s, t)``; default
        ``spinal.frames(points)`` (double reflection).
    t0 : start time.
    reach : R > 0 (default ``radius``).
    falloff_power : p in {2, 3, 4} of the curl parts.
    blend : "c1" or "linear", the region function of ``tool="carry"``.
    """
    from ._frames import frames as _frames

    x, chords = _spine_points(points)
    rho = _positive(radius, "radius")
    dur = _positive(duration, "duration")
    kind = as_choice(kind, "kind", ("translate", "rotate", "twist", "bend"))
    carry = as_choice(tool, "tool", ("push", "carry")) == "carry"
    k = _real(rate, "rate")
    start = _real(t0, "t0")
    reach = rho if reach is None else _positive(reach, "reach")
    if frames is None:
        f = _frames(x)
    else:
        f = as_float_array(frames, "frames")
        if f.shape != (len(x), 3, 3):
            raise ValueError(f"frames: expected shape {(len(x), 3, 3)}, got {f.shape}")
        if not np.isfinite(f).all():
            raise ValueError("frames: must be finite")
        err = np.abs(np.einsum("nji,njk->nik", f, f) - np.eye(3)).max(axis=(1, 2))
        if (err > 1e-6).any() or (np.linalg.det(f) <= 0).any():
            raise ValueError(f"frames: frame {int(np.argmax(err))} is not a rotation matrix")
    s = np.concatenate([[0.0], np.cumsum(chords)])
    head = _row(7, start, dur, rho, reach, _power(falloff_power), float(carry), _blend(blend),
                float(kind == "rotate"), k if kind == "twist" else 0.0,
                k if kind == "bend" else 0.0, len(x))
    body = np.zeros((len(x), ROW))
    body[:, 0] = 8
    body[:, 1:4] = x
    body[:, 4:13] = np.transpose(f, (0, 2, 1)).reshape(-1, 9)  # columns r, s, t
    body[:, 13] = s
    return Field(np.vstack([head, body]), (f"along_path({kind}, {tool})",))
