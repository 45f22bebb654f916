r"""Differential geometry of profile (moulding) surfaces: :func:`profile_surface`.

After Mäurer & Jüttler, *Rational approximation of rotation minimizing frames using
Pythagorean-hodograph cubics* (Journal for Geometry and Graphics 3, 1999; "MJ" below, see
docs/references.md), §2.2–2.3: Prop. 2–3, Cor. 7 with (9), the normal (10), the principal
curvatures (11)–(13), the parabolic lines (14), Prop. 8 and Cor. 9.

A profile surface sweeps a planar cross-section ``c(v) = (a(v), b(v))`` along a spine
``x(u)`` with a rotation-minimising frame (RMF) ``(r, s, t)`` (spinal's columns; MJ's
``(f₂, f₃, t)``, ``s = t × r``)::

    X(u, v) = x(u) + a(v) r(u) + b(v) s(u)

spinal's names follow its sweeps (``u`` along the spine, ``v`` along the profile); MJ write
the spine parameter ``v`` and the profile parameter ``u``. With ``σ = |x′|`` and arc length
``ds = σ du``, the RMF obeys ``t′ = σ(k₁ r + k₂ s)``, ``r′ = −σ k₁ t``, ``s′ = −σ k₂ t``
(no turn about ``t``): ``(k₁, k₂)`` are the normal-development curvatures, the components
of the curvature vector ``κn = k₁ r + k₂ s`` (1/length; MJ (5): ``k₁ = κ cos Ω``,
``k₂ = −κ sin Ω``, ``Ω`` the angle from the principal normal ``n`` to ``r``). Then::

    X_u = σ μ t,          μ = 1 − k₁ a − k₂ b = 1 − κ (a cos Ω − b sin Ω)
    X_v = a′ r + b′ s,    X_u · X_v = 0,  X_uv · N = 0       (MJ Prop. 3: a principal patch)
    N   = (T_b r − T_a s),  T = c′/|c′| the profile's unit tangent                     (MJ (10))

``N`` is the profile's right-hand normal in the normal plane: the outward normal of a
profile that runs counter-clockwise (from ``r`` towards ``s``); it is ``X_v × X_u/|·|`` where
``μ > 0``. With the second fundamental form ``II = X_ij · N`` the principal curvatures are
the normal curvatures of the two parameter directions (1/length)::

    κ_u = (k₁ T_b − k₂ T_a)/μ = κ cos ϑ / μ     along t           (MJ (12), Meusnier)
    κ_v = −κ_c,  κ_c = (a′b″ − a″b′)/|c′|³      along the profile  (MJ (11), signed)
    K   = κ_u κ_v = −κ_c κ cos ϑ / μ,   H = (κ_u + κ_v)/2                               (13)

``cos ϑ = N · n``. MJ's (13) is printed without the sign and the ``1/μ``; the zero set, and
so every statement about parabolic lines, is the same. ``K`` vanishes
(parabolic points) where ``κ_c = 0`` (an inflection of the profile: a line ``v = const``),
``κ = 0`` (an inflection of the spine: ``u = const``) or ``cos ϑ = 0`` (``N ∥ b``, MJ (14)).
The surface is singular where ``X_u = 0``, i.e. ``μ = 0``: the profile meets the curvature
axis (MJ (8)); MJ Cor. 7: ``μ > 0`` everywhere ((9)) excludes singular points. By MJ Prop. 8
and Cor. 9, a convex profile whose tangents turn by ``δ < π`` along a spine whose curvature
vector turns by ``ΔΩ < π − δ`` in the RMF can be turned about ``t`` so that ``K > 0``
everywhere (turned by π more: ``K < 0``); for ``δ ≥ π`` no turn avoids parabolic points.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

import numpy as np
import numpy.typing as npt

from ._frames import estimate_tangents
from ._frames import frames as _frames
from ._profile_contours import _bilinear, _contours
from ._types import Array, Float64Array
from ._validate import (
    MAX_SAMPLES,
    as_bool,
    as_choice,
    as_float_array,
    as_frames,
    as_int,
    as_points,
)
from .curves import Curve

if TYPE_CHECKING:
    from ._mesh import Mesh
    from ._ph import PHSpline

__all__ = ["ProfileSurface", "profile_surface"]

#: Default sample counts of analytic spines and profiles.
_DEFAULT_COUNT = 101

#: A curvature with ``|κ|·size`` below this counts as zero (straight) in the signs.
_FLAT = 1e-10

#: Frames turning about the tangent faster than this fraction of the spine's largest
#: curvature (or of 1/length) are refused as not rotation-minimising.
_TWIST_TOL = 1e-2


# ---------------------------------------------------------------------------------------
# the record


@dataclass(frozen=True, eq=False)
class ProfileSurface:
    r"""The differential geometry of a profile surface on a grid of samples, from
    :func:`profile_surface`. Arrays are read-only; ``(nu, nv)`` arrays are indexed
    ``[spine sample, profile sample]``; curvatures are in 1/length, signed with respect
    to ``normals`` (``II = X_ij · N``: a tube round a counter-clockwise profile has
    negative curvatures on its outside).

    Attributes
    ----------
    u : ndarray (nu,)
        Spine parameters: arc length (sampled spines), the curve's parameter
        (:class:`spinal.curves.Curve`) or the spline parameter ``s ∈ [0, m]``
        (:class:`spinal.ph.PHSpline`).
    v : ndarray (nv,)
        Profile parameters: arc length along sampled profiles, the curve's parameter for
        a profile curve.
    points, normals : ndarray (nu, nv, 3)
        Surface points ``X`` and unit normals ``N`` (MJ (10)).
    frames : ndarray (nu, 3, 3)
        The rotation-minimising frames used, columns ``(r, s, t)``.
    spine_curvature : ndarray (nu, 2)
        ``(k₁, k₂)``: the spine's curvature vector in ``(r, s)`` (``κ² = k₁² + k₂²``).
    profile_tangents : ndarray (nv, 2)
        The profile's unit tangents ``T`` in ``(r, s)``.
    profile_curvature : ndarray (nv,)
        Signed curvature ``κ_c`` of the profile (positive turning from ``r`` to ``s``).
    mu : ndarray (nu, nv)
        ``μ = 1 − k₁ a − k₂ b``: ``X_u = σ μ t``; 0 where the profile meets the curvature
        axis, negative past it.
    curvature_u, curvature_v : ndarray (nu, nv)
        The principal curvatures of the spine direction ``t`` and of the profile
        direction (``κ_u``, ``κ_v``); ``±inf`` where ``μ = 0``.
    k1, k2 : ndarray (nu, nv)
        Principal curvatures, ``k1 ≥ k2``.
    d1, d2 : ndarray (nu, nv, 3)
        Unit principal directions of ``k1`` and ``k2`` (``t`` and the profile tangent
        ``T_a r + T_b s``, in the order of their curvatures).
    gaussian, mean : ndarray (nu, nv)
        ``K = k1 k2`` and ``H = (k1 + k2)/2``.
    parabolic_sign : ndarray (nu, nv) int8
        The sign of ``K`` (−1, 0, +1) as the product of the signs of its factors
        ``−κ_c``, ``κ cos ϑ`` and ``μ``, a factor counting as 0 when the curvature it
        carries is below ``1e-10`` per size of the profile (``κ_c``) or of the spine
        (``κ cos ϑ``). ``parabolic_sign.ravel()`` is per vertex of :meth:`mesh`, and of
        ``spinal.sweep(points, profile, frames=ps.frames, caps=False, miter_limit=1.0,
        profile_closed=...)`` on the same samples when the sweep adds no joins (a smooth
        spine): ``mesh.point_data["parabolic_sign"] = ps.parabolic_sign.ravel()``.
    singular_points : ndarray (k, 2)
        ``(u, v)`` where ``μ = 0`` (MJ Cor. 7): per spine sample, the profile parameters
        where ``μ`` changes sign between neighbouring profile samples (linear
        interpolation in ``v``; exact for straight profile pieces) or vanishes at one.
    singularity_free : bool
        MJ (9) at every sample: ``μ > 0`` (no singular point on the sampled patch).
    convex : bool
        ``K > 0`` at every sample (an elliptic, locally convex patch; MJ Prop. 8).
    profile_turning : float
        ``δ``: the angle range of the profile's tangents (radians; ≥ 2π for a closed one).
    frame_turning : float
        ``ΔΩ = Ω_max − Ω_min``: the angle range of the spine's curvature vector in the RMF
        (radians; NaN where the spine has a zero curvature).
    convexity_criterion : bool
        MJ Cor. 9: the profile is convex (``κ_c`` of one sign, non-zero), the spine's
        curvature non-zero, ``δ < π`` and ``ΔΩ < π − δ`` — then some turn of the profile
        about ``t`` makes ``K > 0`` everywhere (while ``μ > 0``).
    convex_turns : ndarray (2,) or None
        The open interval ``(φ_lo, φ_hi)`` of angles (radians, counter-clockwise from ``r``
        to ``s``, ``φ_lo ∈ (−π, π]``) by which turning the profile gives ``κ_c cos ϑ < 0``
        at every sample, hence ``K > 0`` where ``μ > 0``; ``φ + π`` gives ``K < 0``. None
        unless ``convexity_criterion``.
    closed, profile_closed : bool
        Whether the spine / profile are loops (:meth:`mesh` and :meth:`parabolic_lines`
        join the profile's last sample to its first).
    """

    u: Float64Array
    v: Float64Array
    points: Float64Array
    normals: Float64Array
    frames: Float64Array
    spine_curvature: Float64Array
    profile_tangents: Float64Array
    profile_curvature: Float64Array
    mu: Float64Array
    curvature_u: Float64Array
    curvature_v: Float64Array
    k1: Float64Array
    k2: Float64Array
    d1: Float64Array
    d2: Float64Array
    gaussian: Float64Array
    mean: Float64Array
    parabolic_sign: npt.NDArray[np.int8]
    singular_points: Float64Array
    singularity_free: bool
    convex: bool
    profile_turning: float
    frame_turning: float
    convexity_criterion: bool
    convex_turns: Float64Array | None
    closed: bool
    profile_closed: bool

    def parabolic_lines(self, space: Literal["parameters", "points"] = "parameters") -> list[Float64Array]:
        """The parabolic lines (``K = 0``, MJ (14) and §2.3) as polylines.

        Marching squares on the sample grid of ``K μ = −κ_c κ cos ϑ`` (the zeros of ``K``
        without its poles where the profile crosses the curvature axis, ``μ = 0``; with
        the factors of :attr:`parabolic_sign` below their threshold set to 0): a line
        crosses each grid edge whose ends have ``K μ > 0`` and ``K μ ≤ 0``, at the zero
        interpolated linearly along the edge (2nd order in the sample spacing); a cell
        crossed four times is resolved by the mean of its corners. On a developable part
        (``K ≡ 0``) there is none. Across a closed
        profile's seam the lines continue; a closed spine's seam is not joined (the RMF
        generally does not close, :func:`spinal.closing_angle`).

        Parameters
        ----------
        space : {"parameters", "points"}
            ``"parameters"``: ``(k, 2)`` arrays of ``(u, v)``; ``"points"``: ``(k, 3)``
            surface points, interpolated bilinearly between the samples' points.

        Returns
        -------
        list of ndarray
            One polyline per line; a closed line repeats its first vertex at the end.
        """
        space = as_choice(space, "space", ("parameters", "points"))
        # K μ = −κ_c κ cos ϑ: the zeros of K without its poles on the singular curve
        k, T = self.spine_curvature, self.profile_tangents
        kcos = k[:, :1] * T[None, :, 1] - k[:, 1:] * T[None, :, 0]
        num = -self.profile_curvature[None, :] * kcos
        field = np.where(self.parabolic_sign == 0, 0.0, num)
        lines = _contours(field, self.profile_closed)
        nu = field.shape[0]
        out = []
        for fi, fj in lines:
            if space == "parameters":
                pu = np.interp(fi, np.arange(nu), self.u)
                v_end: float | None = getattr(self, "_v_end")  # noqa: B009 (set by profile_surface)
                vx = np.r_[self.v, v_end] if self.profile_closed else self.v
                pv = np.interp(fj, np.arange(len(vx)), vx)
                out.append(np.stack([pu, pv], axis=1))
            else:
                out.append(_bilinear(self.points, fi, fj, self.profile_closed))
        return out

    def mesh(self) -> Mesh:
        """The sample grid as a :class:`spinal.Mesh` with the surface's normals.

        Vertex ``i·nv + j`` is ``points[i, j]`` (so ``field.ravel()`` of any ``(nu, nv)``
        array is per vertex); two triangles per grid cell, wound so that the right-hand
        normal is :attr:`normals` where ``μ > 0``; a closed profile is joined across its
        seam. ``uv`` holds ``(u, v)``; ``point_data`` holds ``gaussian``, ``mean``, ``k1``,
        ``k2``, ``mu`` and ``parabolic_sign``.
        """
        from ._mesh import Mesh

        nu, nv = self.mu.shape
        cols = nv if self.profile_closed else nv - 1
        i, j = np.meshgrid(np.arange(nu - 1), np.arange(cols), indexing="ij")
        a = i * nv + j
        b = i * nv + (j + 1) % nv
        c = a + nv
        d = b + nv
        faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3),
                                np.stack([b, d, c], -1).reshape(-1, 3)])
        uv = np.stack(np.meshgrid(self.u, self.v, indexing="ij"), -1).reshape(-1, 2)
        data: dict[str, Array] = {k: np.array(getattr(self, k)).reshape(-1)
                for k in ("gaussian", "mean", "k1", "k2", "mu", "parabolic_sign")}
        return Mesh(self.points.reshape(-1, 3), faces, self.normals.reshape(-1, 3), uv,
                    point_data=data)


# ---------------------------------------------------------------------------------------
# the function


def profile_surface(
    spine: Array | Curve | PHSpline,
    profile: Array | Curve,
    u: int | Array | None = None,
    v: int | Array | None = None,
    *,
    frames: Array | None = None,
    initial: Array | None = None,
    closed: bool = False,
    profile_closed: bool = False,
) -> ProfileSurface:
    r"""Normals, principal curvatures, parabolic lines, singular points and convexity of the
    profile (moulding) surface ``X(u, v) = x(u) + a(v) r(u) + b(v) s(u)`` swept with the
    rotation-minimising frame (RMF) ``(r, s, t)`` (Mäurer & Jüttler 1999, "MJ", §2.2–2.3).

    The surface is the one :func:`spinal.sweep` meshes from the same spine, profile and
    frames (without its mitre stretch at corners). Everything is evaluated on the grid of
    spine samples × profile samples. ``u`` runs along the spine and ``v`` along the profile
    (as in the sweeps' texture coordinates; MJ name them the other way round). With the
    curvature vector ``κn = k₁ r + k₂ s`` of the spine (1/length; the RMF relations
    ``t′ = σ(k₁ r + k₂ s)``, ``r′ = −σk₁ t``, ``s′ = −σk₂ t``, ``σ = |x′|``), the profile's
    unit tangent ``T = (T_a, T_b)`` and signed curvature ``κ_c`` (1/length)::

        X_u = σ μ t,   μ = 1 − k₁ a − k₂ b,   X_u · X_v = 0         (MJ Prop. 3)
        N   = T_b r − T_a s                                         (MJ (10))
        κ_u = (k₁ T_b − k₂ T_a)/μ = κ cos ϑ/μ,   κ_v = −κ_c         (MJ (11)–(12))
        K   = κ_u κ_v = −κ_c κ cos ϑ/μ,   H = (κ_u + κ_v)/2         (MJ (13))

    The patch is principal (the ``u`` and ``v`` lines are lines of curvature); ``N`` is the
    outward normal of a counter-clockwise profile; curvatures are signed by
    ``II = X_ij · N``; MJ print (13) without its sign and the ``1/μ``.

    ``cos ϑ = N · n``. Parabolic lines (``K = 0``) are where ``κ_c = 0`` (profile
    inflections), ``κ = 0`` (spine inflections) or ``cos ϑ = 0`` (MJ (14)); singular points
    where ``μ = 0`` (the profile meets the curvature axis; MJ Cor. 7: ``μ > 0``, i.e.
    ``κ(a cos Ω − b sin Ω) < 1`` with ``Ω`` the angle from ``n`` to ``r``, excludes them).
    No derivative of the curvature is needed, so sampled spines need only the RMF and
    ``κn``, and profiles only ``T`` and ``κ_c``. The convexity fields follow MJ Prop. 8 and
    Cor. 9 (see :class:`ProfileSurface`).

    Parameters
    ----------
    spine : array_like (n, 3), spinal.curves.Curve or spinal.ph.PHSpline
        * Samples ``x_0 … x_{n−1}`` (n ≥ 3). The curvature vector at ``x_i`` is that of the
          circle through ``x_{i−1}, x_i, x_{i+1}``, ``κn = 2 (p × w)/|p|²`` with
          ``α = x_{i−1} − x_i``, ``β = x_{i+1} − x_i``, ``w = α × β``,
          ``p = |α|² β − |β|² α`` (exact on circles and straight lines, 2nd order for
          smooth spacing, 0 on collinear samples); at the two ends of an open spine
          ``(k₁, k₂)`` are extrapolated linearly in arc length from the two nearest rows
          (they vary smoothly in an RMF). ``u`` is the arc length (chord sums).
        * An analytic curve: exact ``κn = ((x′ × x″) × x′)/|x′|⁴`` at the parameters
          ``u``; frames by RK4 on the RMF equation (``spinal.frames(curve, u=u,
          method="rk4")``, 4th order).
        * A PH spline: its exact RMF (``spline.rmf(u, exact=True)``, closed form, MJ (30))
          and exact ``κn`` from its derivatives at spline parameters ``u ∈ [0, m]``; at a
          joint the values of the cubic starting there (the curvature jumps: the spline is
          G¹).
    profile : array_like (m, 2) or spinal.curves.Curve
        The cross-section in the normal plane, coordinates along ``(r, s)`` (as in
        :func:`spinal.sweep`): samples (m ≥ 3, an open polyline unless
        ``profile_closed``; tangent and signed curvature from the circle through each
        sample and its neighbours, exact on circles and lines, 2nd order for smooth
        spacing; at open ends the curvature is extrapolated linearly and the tangent taken
        from the end circle; ``v`` is the arc length), or a planar analytic curve whose
        ``z`` vanishes (``x``, ``y`` along ``r``, ``s``; exact derivatives at ``v``).
    u : int or array_like (nu,), optional
        Analytic and PH spines only: increasing parameters, or a count (uniform over the
        curve's domain / ``[0, m]``). Default: 101 samples of a curve, 16 per cubic of a
        spline (:meth:`spinal.ph.PHSpline.samples`).
    v : int or array_like (nv,), optional
        Profile curves only: increasing parameters or a count over the domain (default
        101).
    frames : array_like (n, 3, 3), optional
        Sampled and analytic spines: rotation-minimising frames (columns ``r, s, t``)
        instead of the default ``spinal.frames(points)`` (double reflection) or RK4.
        Frames that turn about the tangent faster than 1 % of the spine's largest curvature
        (or of 1/length), measured against the minimal rotation between neighbouring
        tangents, are refused: a twisted sweep is not a profile surface and its patch is
        not principal.
    initial : array_like (3,), optional
        The reference vector ``r`` at the first sample (projected onto the normal plane) for
        the default frames (sampled, analytic, PH spines); it turns the profile about the
        spine, hence ``Ω₀`` of MJ Cor. 9.
    closed : bool
        Sampled spines: the samples form a loop (a repeated first point at the end is
        dropped): curvatures and tangents are estimated across the seam. The default frames
        are still the RMF from row 0, not closed up (a profile surface's frame does not
        twist; it meets itself at the seam turned by :func:`spinal.closing_angle`).
    profile_closed : bool
        The profile is a loop (a repeated first vertex at the end is dropped).

    Returns
    -------
    ProfileSurface
        The record of normals, curvatures, signs, singular points and convexity; its
        :meth:`~ProfileSurface.parabolic_lines` and :meth:`~ProfileSurface.mesh`.

    Raises
    ------
    ValueError
        Wrong shapes, non-finite values, repeated consecutive samples, too few samples,
        parameters not increasing or outside the domain, a profile curve off the plane
        ``z = 0`` or with a zero derivative, frames that are not rotation matrices or not
        rotation-minimising; the message names the argument.
    TypeError
        ``u``/``v``/``frames``/``closed`` with a spine or profile they do not apply to.
    """
    from .ph import PHSpline

    closed = as_bool(closed, "closed")
    profile_closed = as_bool(profile_closed, "profile_closed")
    init = None
    if initial is not None:
        init = as_float_array(initial, "initial")
        if init.shape != (3,) or not np.all(np.isfinite(init)):
            raise ValueError(f"initial: expected 3 finite values, got shape {init.shape}")

    # -- profile: points (nv, 2), unit tangents, signed curvature, parameters
    c, T, kc, vv, prof_size, v_end = _profile(profile, v, profile_closed)

    # -- spine: points, frames, curvature vectors, parameters
    if isinstance(spine, PHSpline):
        if frames is not None:
            raise TypeError("frames: not accepted with a PHSpline (its exact RMF is used; "
                            "turn it with initial)")
        if closed:
            raise TypeError("closed: applies to sampled spines only")
        uu = _spline_params(spine, u)
        F = spine.rmf(uu, initial=init, exact=True)
        x = spine.evaluate(uu)
        kn = _curvature_vector(spine.evaluate(uu, 1), spine.evaluate(uu, 2))
        spine_size = _size(x)
    elif isinstance(spine, Curve):
        if closed:
            raise TypeError("closed: applies to sampled spines only")
        uu = _curve_params(spine, u, "u")
        x = spine.point(uu)
        kn = _curvature_vector(spine.d1(uu), spine.d2(uu))
        spine_size = _size(x)
        if frames is None:
            F = _frames(spine, u=uu, method="rk4", initial=init)
        else:
            if init is not None:
                raise TypeError("initial: only for the default frames (turn the frames given)")
            F = _checked_frames(frames, x, uu, kn, spine_size, spine.tangent(uu))
    else:
        if u is not None:
            raise TypeError("u: only with an analytic or PH spine (a sampled spine's rows "
                            "are its samples; u is their arc length)")
        x = as_points(spine, "spine")
        if not np.all(np.isfinite(x)):
            raise ValueError("spine: contains non-finite values")
        floor = _repeat_floor(x)
        if closed and len(x) > 1 and np.abs(x[-1] - x[0]).max() <= floor:
            x = x[:-1]
        if len(x) < 3:
            raise ValueError(f"spine: expected at least 3 samples, got {len(x)}")
        rows = np.flatnonzero(np.abs(np.diff(x, axis=0)).max(axis=1) <= floor)
        if rows.size:
            raise ValueError(f"spine: repeated consecutive points at rows {rows[:10].tolist()}")
        h = np.linalg.norm(np.diff(x, axis=0), axis=1)
        uu = np.r_[0.0, np.cumsum(h)]
        kn = _circle_curvature(x, closed)
        spine_size = _size(x)
        if frames is None:
            tg = estimate_tangents(x, closed=closed)
            F = _frames(x, tg, initial=init)
        else:
            if init is not None:
                raise TypeError("initial: only for the default frames (turn the frames given)")
            F = _checked_frames(frames, x, uu, kn, spine_size, None)
    F = np.ascontiguousarray(F)
    r, s, t = F[:, :, 0], F[:, :, 1], F[:, :, 2]
    k = np.stack([np.einsum("ij,ij->i", kn, r), np.einsum("ij,ij->i", kn, s)], axis=1)
    if not isinstance(spine, (PHSpline, Curve)) and not closed:
        k = _extrapolate_ends(k, uu)

    # -- the surface
    a, b = c[:, 0], c[:, 1]
    Ta, Tb = T[:, 0], T[:, 1]
    P = x[:, None, :] + a[None, :, None] * r[:, None, :] + b[None, :, None] * s[:, None, :]
    N = Tb[None, :, None] * r[:, None, :] - Ta[None, :, None] * s[:, None, :]
    mu = 1.0 - k[:, :1] * a[None, :] - k[:, 1:] * b[None, :]
    kcos = k[:, :1] * Tb[None, :] - k[:, 1:] * Ta[None, :]        # κ cos ϑ
    with np.errstate(divide="ignore", invalid="ignore"):
        cu = kcos / mu
    cv = np.broadcast_to(-kc[None, :], mu.shape).copy()
    K = cu * cv
    H = 0.5 * (cu + cv)
    du = np.broadcast_to(t[:, None, :], P.shape)
    dv = Ta[None, :, None] * r[:, None, :] + Tb[None, :, None] * s[:, None, :]
    first = np.greater_equal(cu, cv)[..., None]
    k1 = np.maximum(cu, cv)
    k2 = np.minimum(cu, cv)
    # NaN (0/0 at μ = 0 with cos ϑ = 0) sorts as itself
    k1 = np.where(np.isnan(cu), cu, k1)
    k2 = np.where(np.isnan(cu), cv, k2)
    d1 = np.where(first, du, dv)
    d2 = np.where(first, dv, du)

    # -- signs of the factors of K = (−κ_c)(κ cos ϑ)(1/μ)
    s_prof = np.where(np.abs(kc) * prof_size <= _FLAT, 0, -np.sign(kc)).astype(np.int8)
    s_spine = np.where(np.abs(kcos) * spine_size <= _FLAT, 0, np.sign(kcos)).astype(np.int8)
    sign = (s_prof[None, :] * s_spine * np.sign(mu).astype(np.int8)).astype(np.int8)

    sing = _singular_points(mu, uu, vv, v_end)
    conv = _convexity(T, kc, k, prof_size, spine_size, profile_closed)

    def ro(arr: np.ndarray) -> np.ndarray:
        arr = np.ascontiguousarray(arr)
        arr.setflags(write=False)
        return arr

    rec = ProfileSurface(
        u=ro(uu.copy()), v=ro(vv.copy()), points=ro(P), normals=ro(N), frames=ro(F.copy()),
        spine_curvature=ro(k), profile_tangents=ro(T.copy()), profile_curvature=ro(kc.copy()),
        mu=ro(mu), curvature_u=ro(cu), curvature_v=ro(cv), k1=ro(k1), k2=ro(k2),
        d1=ro(d1), d2=ro(d2), gaussian=ro(K), mean=ro(H), parabolic_sign=ro(sign),
        singular_points=ro(sing), singularity_free=bool(np.all(mu > 0)),
        convex=bool(np.all(K > 0)), profile_turning=conv[0], frame_turning=conv[1],
        convexity_criterion=conv[2],
        convex_turns=None if conv[3] is None else ro(conv[3]),
        closed=closed, profile_closed=profile_closed)
    object.__setattr__(rec, "_v_end", v_end)
    return rec


# ---------------------------------------------------------------------------------------
# inputs


def _size(p: np.ndarray) -> float:
    """The bounding-box diagonal (1 for a single point), the length scale of the signs."""
    d = float(np.linalg.norm(p.max(axis=0) - p.min(axis=0)))
    return d if d > 0 else 1.0


def _repeat_floor(p: np.ndarray) -> float:
    """The largest coordinate difference that counts as a repeated point: ``2⁻⁴⁰`` of the
    bounding box's largest side, the rule of :func:`spinal.frames` and :func:`spinal.sweep`."""
    return float(np.max(p.max(axis=0) - p.min(axis=0))) * 2.0**-40


def _count_or_values(x: object, name: str, domain: tuple[float, float], default: int) -> np.ndarray:
    if x is None:
        x = default
    if isinstance(x, (int, np.integer)) and not isinstance(x, bool):
        n = as_int(x, name, 2, MAX_SAMPLES, out_of_bounds=lambda q: (
            f"a sample count must be at least 2 and at most {MAX_SAMPLES:,}, got {q}"))
        return np.linspace(domain[0], domain[1], n)
    arr = as_float_array(x, name)
    if arr.ndim != 1 or arr.size < 2:
        raise ValueError(f"{name}: expected a count or a 1-D array of at least 2 values, "
                         f"got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: contains non-finite values")
    if not np.all(np.diff(arr) > 0):
        raise ValueError(f"{name}: must be strictly increasing")
    return np.array(arr, dtype=float)


def _curve_params(curve: Curve, x: object, name: str) -> np.ndarray:
    return _count_or_values(x, name, curve.domain, _DEFAULT_COUNT)


def _spline_params(spline: PHSpline, x: object) -> np.ndarray:
    m = spline.segments
    if x is None:
        out: np.ndarray = spline.samples(16)
        return out
    uu = _count_or_values(x, "u", (0.0, float(m)), _DEFAULT_COUNT)
    if uu[0] < 0 or uu[-1] > m:
        raise ValueError(f"u: spline parameters must lie within [0, {m}]")
    return uu


def _profile(profile: Array | Curve, v: object, profile_closed: bool
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float, float | None]:
    """``(c (nv, 2), T (nv, 2), κ_c (nv,), v (nv,), size, v_end)``; ``v_end`` is the
    parameter at which a closed profile returns to its first sample (None when open)."""
    if isinstance(profile, Curve):
        vv = _curve_params(profile, v, "v")
        p, d1, d2 = profile.point(vv), profile.d1(vv), profile.d2(vv)
        size = _size(p[:, :2])
        if np.any(np.abs(p[:, 2]) > 1e-12 * size) or np.any(np.abs(d1[:, 2]) > 1e-12 * (
                1 + np.abs(d1[:, :2]).max())):
            raise ValueError("profile: a profile curve must lie in the plane z = 0 (its x, y "
                             "are the coordinates along r, s)")
        v_end = None
        if profile_closed:
            v_end = vv[-1] + (vv[-1] - vv[-2])
            if np.allclose(p[0], p[-1], rtol=0, atol=1e-12 * size):
                v_end = vv[-1]
                p, d1, d2, vv = p[:-1], d1[:-1], d2[:-1], vv[:-1]
        speed = np.hypot(d1[:, 0], d1[:, 1])
        if np.any(speed == 0):
            raise ValueError(f"profile: the profile curve has a zero derivative at v = "
                             f"{vv[np.flatnonzero(speed == 0)[0]]}")
        T = d1[:, :2] / speed[:, None]
        kc = (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / speed**3
        return np.ascontiguousarray(p[:, :2]), T, kc, vv, size, v_end
    if v is not None:
        raise TypeError("v: only with a profile curve (a sampled profile's rows are its "
                        "samples; v is their arc length)")
    c = as_float_array(profile, "profile")
    if c.ndim != 2 or c.shape[1] != 2:
        raise ValueError(f"profile: expected an array of shape (m, 2), got shape {c.shape}")
    if not np.all(np.isfinite(c)):
        raise ValueError("profile: contains non-finite values")
    c = np.array(c, dtype=float)
    floor = _repeat_floor(c)
    if profile_closed and len(c) > 1 and np.abs(c[-1] - c[0]).max() <= floor:
        c = c[:-1]
    if len(c) < 3:
        raise ValueError(f"profile: expected at least 3 samples, got {len(c)}")
    e = np.diff(np.vstack([c, c[:1]]) if profile_closed else c, axis=0)
    rows = np.flatnonzero(np.abs(e).max(axis=1) <= floor)
    if rows.size:
        raise ValueError(f"profile: repeated consecutive points at rows {rows[:10].tolist()}")
    h = np.hypot(e[:, 0], e[:, 1])
    vv = np.r_[0.0, np.cumsum(h[: len(c) - 1])]
    T, kc = _circle_2d(c, profile_closed, vv)
    return c, T, kc, vv, _size(c), (float(vv[-1] + h[-1]) if profile_closed else None)


def _circle_2d(c: np.ndarray, closed: bool, vv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit tangents and signed curvatures of a 2-D polyline from the circle through each
    sample and its neighbours: ``T ∝ α/|α|² + β/|β|²`` (α, β the chords in and out),
    ``κ = 2 (α × β)/(|α||β||α + β|)``."""
    n = len(c)
    prev = np.roll(c, 1, axis=0)
    nxt = np.roll(c, -1, axis=0)
    al = c - prev
    be = nxt - c
    la = np.hypot(al[:, 0], al[:, 1])
    lb = np.hypot(be[:, 0], be[:, 1])
    g = al + be
    lg = np.hypot(g[:, 0], g[:, 1])
    cross = al[:, 0] * be[:, 1] - al[:, 1] * be[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        kc = 2.0 * cross / (la * lb * lg)
        T = al / la[:, None] ** 2 + be / lb[:, None] ** 2
    kc = np.where(lg > 0, kc, 0.0)
    if not closed:
        # the end circles (through the first / last three samples)
        T[0] = _reflect(T[1], c[1] - c[0])
        T[-1] = _reflect(T[-2], c[-1] - c[-2])
        if n >= 4:
            kc[0] = kc[1] + (kc[1] - kc[2]) * (vv[1] - vv[0]) / (vv[2] - vv[1])
            kc[-1] = kc[-2] + (kc[-2] - kc[-3]) * (vv[-1] - vv[-2]) / (vv[-2] - vv[-3])
        else:
            kc[0] = kc[-1] = kc[1]
    nrm = np.hypot(T[:, 0], T[:, 1])
    if np.any(~(nrm > 0)):
        raise ValueError("profile: the profile doubles back on itself (a sample's chords "
                         "point in opposite directions)")
    return T / nrm[:, None], kc


def _reflect(t: np.ndarray, chord: np.ndarray) -> np.ndarray:
    """The tangent at the far end of a circular arc: ``t`` reflected in the chord."""
    e = chord / np.hypot(*chord)
    out: np.ndarray = 2 * np.dot(t / np.hypot(*t), e) * e - t / np.hypot(*t)
    return out


def _curvature_vector(d1: np.ndarray, d2: np.ndarray) -> np.ndarray:
    """``κn = ((x′ × x″) × x′)/|x′|⁴``."""
    sp2 = np.einsum("ij,ij->i", d1, d1)
    if np.any(sp2 == 0):
        raise ValueError("spine: the curve is not regular (zero derivative) at a sample")
    out: np.ndarray = np.cross(np.cross(d1, d2), d1) / sp2[:, None] ** 2
    return out


def _circle_curvature(x: np.ndarray, closed: bool) -> np.ndarray:
    """The curvature vector of the circle through each sample and its neighbours
    (``2 (p × w)/|p|²``; zero on collinear samples); the end rows of an open spine get
    their neighbour's (replaced by :func:`_extrapolate_ends`)."""
    al = np.roll(x, 1, axis=0) - x
    be = np.roll(x, -1, axis=0) - x
    w = np.cross(al, be)
    p = (np.einsum("ij,ij->i", al, al)[:, None] * be
         - np.einsum("ij,ij->i", be, be)[:, None] * al)
    pp = np.einsum("ij,ij->i", p, p)
    with np.errstate(divide="ignore", invalid="ignore"):
        kn = 2.0 * np.cross(p, w) / pp[:, None]
    kn[~(pp > 0)] = 0.0
    if not closed:
        kn[0], kn[-1] = kn[1], kn[-2]
    out: np.ndarray = kn
    return out


def _extrapolate_ends(k: np.ndarray, uu: np.ndarray) -> np.ndarray:
    """``(k₁, k₂)`` at the two ends of an open spine, linear in arc length from the next
    two rows (the rows' own circles would be 1st order there)."""
    k = k.copy()
    if len(k) >= 4:
        k[0] = k[1] + (k[1] - k[2]) * (uu[1] - uu[0]) / (uu[2] - uu[1])
        k[-1] = k[-2] + (k[-2] - k[-3]) * (uu[-1] - uu[-2]) / (uu[-2] - uu[-3])
    return k


def _checked_frames(frames: Array, x: np.ndarray, uu: np.ndarray, kn: np.ndarray, size: float,
                    tangents: np.ndarray | None) -> np.ndarray:
    """User frames: rotation matrices, one per sample, without a turn about the tangent
    beyond :data:`_TWIST_TOL`."""
    F, _ = as_frames(frames, "frames", len(x))
    if not np.all(np.isfinite(F)):
        raise ValueError("frames: contains non-finite values")
    err = np.abs(np.einsum("nji,njk->nik", F, F) - np.eye(3)).max(axis=(1, 2))
    det = np.linalg.det(F)
    bad = np.flatnonzero((err > 1e-6) | (det < 0))
    if bad.size:
        raise ValueError(f"frames: not rotation matrices (orthonormal, det +1) at rows "
                         f"{bad[:10].tolist()}")
    t = F[:, :, 2]
    ref = tangents if tangents is not None else np.gradient(x, uu, axis=0)
    if np.any(np.einsum("ij,ij->i", t, ref) <= 0):
        rows = np.flatnonzero(np.einsum("ij,ij->i", t, ref) <= 0)
        raise ValueError(f"frames: the tangent column t points backwards along the spine at "
                         f"rows {rows[:10].tolist()}")
    r0, t0, r1, t1 = F[:-1, :, 0], t[:-1], F[1:, :, 0], t[1:]
    w = np.cross(t0, t1)
    cc = np.einsum("ij,ij->i", t0, t1)
    # r0 carried by the minimal rotation taking t0 to t1 (Rodrigues)
    rr = (r0 * cc[:, None] + np.cross(w, r0)
          + w * (np.einsum("ij,ij->i", w, r0) / (1.0 + cc))[:, None])
    twist = np.arctan2(np.einsum("ij,ij->i", np.cross(rr, r1), t1),
                       np.einsum("ij,ij->i", rr, r1))
    h = np.linalg.norm(np.diff(x, axis=0), axis=1)
    if np.any(h == 0):
        raise ValueError("frames: the spine has repeated consecutive points")
    rate = np.abs(twist) / h
    length = float(h.sum())
    kmax = float(np.linalg.norm(kn, axis=1).max())
    limit = _TWIST_TOL * max(kmax, 1.0 / length if length > 0 else 0.0)
    if not np.all(rate <= limit):  # NaN: a tangent reversed between neighbours
        i = int(np.argmax(np.where(np.isnan(rate), np.inf, rate)))
        raise ValueError(f"frames: not rotation-minimising: they turn about the tangent by "
                         f"{twist[i]:.3g} rad between rows {i} and {i + 1} ({rate[i]:.3g} "
                         f"rad per length; at most {limit:.3g} is accepted)")
    return F


# ---------------------------------------------------------------------------------------
# singular points, convexity


def _singular_points(mu: np.ndarray, uu: np.ndarray, vv: np.ndarray, v_end: float | None
                     ) -> np.ndarray:
    profile_closed = v_end is not None
    vx = np.r_[vv, v_end] if profile_closed else vv
    out = []
    zi, zj = np.nonzero(mu == 0)
    out += [(uu[i], vv[j]) for i, j in zip(zi, zj, strict=True)]
    m2 = np.roll(mu, -1, axis=1) if profile_closed else mu[:, 1:]
    m1 = mu if profile_closed else mu[:, :-1]
    ci, cj = np.nonzero(m1 * m2 < 0)
    for i, j in zip(ci, cj, strict=True):
        f = m1[i, j] / (m1[i, j] - m2[i, j])
        out.append((uu[i], vx[j] + f * (vx[j + 1] - vx[j])))
    arr = np.array(sorted(out), dtype=float).reshape(-1, 2)
    return arr


def _convexity(T: np.ndarray, kc: np.ndarray, k: np.ndarray, prof_size: float,
               spine_size: float, profile_closed: bool
               ) -> tuple[float, float, bool, np.ndarray | None]:
    """``(δ, ΔΩ, Cor. 9 criterion, interval of turns or None)``."""
    gamma = np.unwrap(np.arctan2(T[:, 1], T[:, 0]))
    delta = float(gamma.max() - gamma.min())
    if profile_closed:  # a loop's tangent turns all the way round
        ext = np.unwrap(np.r_[gamma, np.arctan2(T[0, 1], T[0, 0])])
        delta = max(2 * np.pi, float(ext.max() - ext.min()))
    kappa = np.hypot(k[:, 0], k[:, 1])
    spine_bent = bool(np.all(kappa * spine_size > _FLAT))
    if spine_bent:
        beta = np.unwrap(np.arctan2(k[:, 1], k[:, 0]))   # the angle of κn in (r, s)
        drange = float(beta.max() - beta.min())
    else:
        beta = None
        drange = float("nan")
    convex_prof = bool(np.all(kc * prof_size > _FLAT) or np.all(kc * prof_size < -_FLAT))
    crit = bool(convex_prof and spine_bent and delta < np.pi and drange < np.pi - delta)
    turns = None
    if crit:
        alpha = gamma - np.pi / 2                         # the angle of N in (r, s)
        # κ_c > 0 needs cos(α + φ − β) < 0, κ_c < 0 needs it > 0, for every pair
        mid = np.pi if kc[0] > 0 else 0.0
        lo = mid - np.pi / 2 + beta.max() - alpha.min()
        hi = mid + np.pi / 2 + beta.min() - alpha.max()
        shift = 2 * np.pi * np.ceil((lo - np.pi) / (2 * np.pi))
        turns = np.array([lo - shift, hi - shift])
    return delta, drange, crit, turns
