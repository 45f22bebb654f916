"""Moving frames along curves: the Python face of ``spinal._core``."""

from __future__ import annotations

from typing import Any

import numpy as np

from . import _core
from ._validate import as_bool, as_choice, as_float_array, as_int, as_offsets, as_points
from .curves import Curve

__all__ = ["closing_angle", "estimate_tangents", "frames"]

METHODS = ("double_reflection", "projection", "rotation", "frenet", "rk4")
REFLECTIONS = ("chord", "tangents")
TANGENT_RULES = ("five_point", "five_point_uniform", "circle")


def _orientation(x: Any, name: str, curves: int, bundle: bool):
    """Split an initial/end argument into (vectors (k,3), frames (k,3,3)) for the core."""
    if x is None:
        return None, None
    a = as_float_array(x, name)
    if a.shape == (3,):
        return np.ascontiguousarray(a[None, :]), None
    if bundle and a.shape == (curves, 3):
        return np.ascontiguousarray(a), None
    if a.shape == (3, 3):
        return None, np.ascontiguousarray(a[None])
    if bundle and a.shape == (curves, 3, 3):
        return None, np.ascontiguousarray(a)
    expect = "(3,) or (3, 3)" + (f", ({curves}, 3) or ({curves}, 3, 3)" if bundle else "")
    raise ValueError(f"{name}: expected shape {expect}, got {a.shape}")


def _analytic(curve: Curve, u: Any):
    """Points, parameters and exact derivatives at the samples and midpoints."""
    if u is None:
        raise TypeError("u: required with an analytic curve (parameter values or a sample count)")
    if isinstance(u, (int, np.integer)) and not isinstance(u, bool):
        count = as_int(u, "u", minimum=2)
        try:
            uu = curve.parameters(count)
        except MemoryError:
            raise MemoryError(f"u: {count} samples do not fit in memory") from None
    else:
        uu = as_float_array(u, "u")
        if uu.ndim != 1 or uu.size < 2:  # the midpoints below need two values
            raise ValueError(f"u: expected a 1-D array of at least 2 values, got shape {uu.shape}")
    uu = np.ascontiguousarray(uu)
    full = np.empty(2 * uu.size - 1)
    full[0::2] = uu
    full[1::2] = 0.5 * (uu[:-1] + uu[1:])
    return (
        np.ascontiguousarray(curve.point(uu)),
        uu,
        np.ascontiguousarray(curve.d1(full)),
        np.ascontiguousarray(curve.d2(full)),
    )


def _compute(points, tangents, method, initial, closed, end, turns, reflection, u,
             lengths, offsets, points_arg="points"):
    method = as_choice(method, "method", METHODS)
    reflection = as_choice(reflection, "reflection", REFLECTIONS)
    closed = as_bool(closed, "closed")
    turns = as_int(turns, "turns")
    if isinstance(points, Curve):
        if tangents is not None:
            raise TypeError("tangents: not accepted with an analytic curve (its exact tangents are used)")
        if lengths is not None or offsets is not None:
            raise TypeError("lengths, offsets: not accepted with an analytic curve")
        if reflection != "chord":
            raise ValueError("reflection: 'tangents' applies to sampled curves only")
        pts, uu, d1, d2 = _analytic(points, u)
        iv, if_ = _orientation(initial, "initial", 1, False)
        ev, ef = _orientation(end, "end", 1, False)
        out, angle = _core.frames_analytic(pts, uu, d1, d2, method, closed, iv, if_, ev, ef, turns)
        return out, np.array([angle]), False
    if u is not None:
        raise TypeError("u: only used with an analytic curve from spinal.curves")
    pts = None if points is None else as_points(points, points_arg)
    tgs = None if tangents is None else as_points(tangents, "tangents")
    if pts is None and (tgs is None or reflection != "tangents"):
        raise TypeError("points: required (only reflection='tangents' works from tangents alone)")
    rows = (pts if pts is not None else tgs).shape[0]
    offs, bundle = as_offsets(rows, lengths, offsets)
    curves = offs.size - 1
    iv, if_ = _orientation(initial, "initial", curves, bundle)
    ev, ef = _orientation(end, "end", curves, bundle)
    # reflection="tangents": the chords of double reflection come from a quadrature of the
    # tangents (the core's `tangent_chords` flag)
    chords_from_tangents = reflection == "tangents"
    out, angles = _core.frames_sampled(
        pts, tgs, offs, method, "five_point", chords_from_tangents, closed,
        iv, if_, ev, ef, turns, points_arg,
    )
    return out, angles, bundle


def _spine_frames(points, name: str, initial=None) -> np.ndarray:
    """The default frames of one curve passed to a spinal function as ``name`` (errors about
    the points name it)."""
    out, _, _ = _compute(points, None, "double_reflection", initial, False, None, 0, "chord",
                         None, None, None, points_arg=name)
    return out


def frames(
    points,
    tangents=None,
    *,
    method: str = "double_reflection",
    initial=None,
    closed: bool = False,
    end=None,
    turns: int = 0,
    reflection: str = "chord",
    u=None,
    lengths=None,
    offsets=None,
) -> np.ndarray:
    r"""Moving frames along a curve: ``(n, 3, 3)`` rotation matrices, columns ``(r, s, t)``.

    ``frames[i][:, 2] = t_i`` is the unit tangent, ``frames[i][:, 0] = r_i`` the reference
    vector (⟂ t_i) and ``frames[i][:, 1] = s_i = t_i × r_i``. Each ``frames[i]`` is a proper
    rotation (orthonormal, det +1), so ``x_i + frames[i] @ (a, b, 0)`` is a point of the normal
    plane and ``scipy.spatial.transform.Rotation.from_matrix(frames)`` accepts the result.

    Parameters
    ----------
    points : array_like (n, 3) or spinal.curves.Curve
        Samples ``x_0 … x_{n−1}`` (n ≥ 2; any real dtype and memory layout; never modified),
        or an analytic curve together with ``u``.
    tangents : array_like (n, 3), optional
        Tangent directions at the samples (normalised here). Without them the unit tangents
        are estimated from the points by :func:`estimate_tangents` (5-point differences in
        chord length, one-sided at open ends, periodic when ``closed``), which keeps double
        reflection 4th order for any smooth spacing; 3–4 points use the circle through
        neighbours (2nd order), 2 points the chord.
    method : str
        * ``"double_reflection"`` (default): the rotation-minimising frame (RMF) by two
          reflections per segment (Wang, Jüttler, Zheng & Liu, ACM TOG 27(1), 2008). 4th
          order; exact on straight lines, planar and spherical curves; symmetric under
          reversal; invariant under rigid motions, scaling and sphere inversions.
        * ``"rotation"``: the RMF by the minimal rotation between consecutive tangents
          (Bloomenthal 1990; discrete parallel transport / Bishop frame). 2nd order.
        * ``"projection"``: the RMF by projecting along each chord (Klok 1986). 2nd order,
          depends on ``initial``.
        * ``"frenet"``: the Frenet frame ``r = N`` (towards the centre of curvature),
          ``s = B``; exact on analytic curves, from sampled points ``N`` points to the centre
          of the circle through each sample and its neighbours (2nd order; 1st order at the
          two end samples; exact on circles, exactly straight on collinear samples). Where the curvature vanishes (inflection samples, straight runs) it is
          undefined; there the frame is carried by double reflection from the last defined
          frame and the mismatch with the next one is spread linearly in arc length, so the
          filled frames are continuous; runs at open ends are carried from the nearest
          defined frame; a straight curve gets an RMF. ``initial``, ``end`` and ``turns`` do
          not apply. (The Frenet frame itself turns by π across an inflection.)
        * ``"rk4"``: classical Runge–Kutta on the RMF ODE ``r′ = (x′ × x″)/|x′|² × r``
          with the normal-plane projection after each step; analytic curves only. 4th order.
    initial : array_like (3,) or (3, 3), optional
        Reference vector at the first sample (projected onto the normal plane and
        normalised), or a whole frame (rotation matrix, columns r, s, t; its r is used and its
        t must agree with the tangent within 1e-3 rad). Default: the principal normal at the
        first sample where the curvature is not negligible (``κ·diag > 1e-9``, diag the
        bounding-box diagonal), carried back to the start along the frames; on a straight
        curve, the world axis least aligned with ``t_0`` projected onto the normal plane.
        The default is deterministic and moves with the curve under rigid motions.
    closed : bool
        The points form a loop (a repeated first point at the end is accepted and gets the
        first frame again). Tangents are estimated periodically, the closing segment is
        included, and the RMF's closing angle ``α`` (see :func:`closing_angle`) plus
        ``2π·turns`` is distributed linearly in arc length, ``α s/L``, so the frames meet
        across the seam. Linear in arc length is the minimiser of ``∫(κ² + α′²) ds`` (Wang et
        al. §6.3).
    end : array_like (3,) or (3, 3), optional
        A prescribed reference vector (or frame) at the last sample; the angle from the RMF to
        it (in (−π, π], plus ``2π·turns``) is distributed linearly in arc length, so the last
        frame meets it exactly.
    turns : int
        Extra full turns added to the closing or end twist (``k`` in ``α + 2πk``).
    reflection : {"chord", "tangents"}
        ``"tangents"``: double reflection with the chords replaced by the 4th-order quadrature
        ``13(t_i + t_{i+1}) − (t_{i−1} + t_{i+2})`` of the tangents (TOG §6.2; Adams–Moulton
        weights at the ends); then ``points`` may be ``None`` and ``tangents`` must be given
        at ≥ 4 samples of a uniform parameter step (arc-length weights become uniform).
    u : int or array_like (n,), optional
        With an analytic curve: strictly increasing parameter values, or a sample count over
        ``curve.domain``. Exact tangents are used, arc lengths by Simpson's rule.
    lengths, offsets : array_like of int, optional
        Many curves in one call: ``points`` holds all curves back to back, ``lengths[c]`` rows
        each (or ``offsets``, C + 1 start rows ending at n). Curves are computed in parallel;
        ``initial``/``end`` may be given per curve as (C, 3) or (C, 3, 3). Long single curves
        use all cores too (a parallel prefix scan of the per-segment rotations).

    Returns
    -------
    ndarray (n, 3, 3) float64
        One frame per input row.

    Raises
    ------
    TypeError
        Non-numeric input, wrong argument types.
    ValueError
        Wrong shapes, fewer than 2 points (3 for a closed curve), NaN/inf, repeated
        consecutive points (zero-length segments), zero tangents, a cusp or a segment whose
        chord runs against its tangents (``(x_{i+1} − x_i)·(t_i + t_{i+1}) ≤ 0``: a reversal
        or far too coarse a sampling), an ``initial``/``end`` vector parallel to the tangent.
        The message names the argument and the row.

    Examples
    --------
    >>> import numpy as np, spinal
    >>> u = np.linspace(0, 4 * np.pi, 200)
    >>> F = spinal.frames(np.c_[np.cos(u), np.sin(u), 0.2 * u])
    >>> F.shape
    (200, 3, 3)
    """
    out, _, _ = _compute(points, tangents, method, initial, closed, end, turns, reflection, u,
                         lengths, offsets)
    return out


def closing_angle(
    points,
    tangents=None,
    *,
    method: str = "double_reflection",
    reflection: str = "chord",
    u=None,
    lengths=None,
    offsets=None,
):
    r"""The closing (holonomy) angle of the rotation-minimising frame of a closed curve.

    Carry a reference vector ``r_0`` once round the loop with the RMF; the result ``r_n``
    differs from ``r_0`` by a rotation about ``t_0``. The closing angle is the signed angle
    from ``r_n`` to ``r_0`` about ``t_0``, in (−π, π] radians (right-handed about the
    tangent); it does not depend on ``r_0``, and equals the total torsion ``∮τ ds`` mod 2π
    where the Frenet frame exists (the RMF turns against the Frenet frame at the rate
    ``−τ``). ``frames(..., closed=True)`` spreads exactly this angle (plus ``2π·turns``)
    along the curve. Example: the torus knot of Wang et al. (2008) gives −2.8757 rad.

    Takes the arguments of :func:`frames` (the points are treated as a loop). Returns a float,
    or a (C,) array for a bundle.
    """
    out, angles, bundle = _compute(points, tangents, method, None, True, None, 0, reflection,
                                   u, lengths, offsets)
    del out
    return angles if bundle else float(angles[0])


def estimate_tangents(points, *, closed: bool = False, method: str = "five_point") -> np.ndarray:
    r"""Unit tangents estimated from sampled points, ``(n, 3)``.

    * ``"five_point"`` (default): the derivative at ``x_i`` of the quartic through the five
      samples around it (one-sided at open ends, periodic when ``closed``), parameterised by
      cumulative chord length (Lagrange weights by Fornberg's algorithm). For equal chords
      these are the 5-point formulas of Wang et al. (2008, §6.1),
      ``x_{i−2} − 8x_{i−1} + 8x_{i+1} − x_{i+2}``; for unequal spacing the direction stays
      O(h⁴) accurate and straight runs give the exact direction. Double reflection with these
      tangents is 4th order. Where the estimate turns more than 60° away from the
      ``"circle"`` estimate (at a kink next to very uneven chords the quartic can swing round
      and point backwards), the circle estimate is used; on smooth samplings the two agree
      to O(h²), so this never triggers there.
    * ``"five_point_uniform"``: the paper's stencils with the sample index as parameter:
      O(h⁴) only if the samples come from a uniform step of a smooth parameterisation
      (kept to reproduce the paper; it can point backwards on very uneven spacing).
    * ``"circle"``: the tangent of the circle through each point and its two neighbours,
      ``|b|² a + |a|² b`` with ``a = x_i − x_{i−1}``, ``b = x_{i+1} − x_i`` (Zheng 2008 §7.1,
      whose printed weights ``|b| a + |a| b`` are exact only for equal chords); exact on
      circles for any spacing, O(h²) in general.

    With 3–4 points the circle rule is used, with 2 points the chord. A closed curve may
    repeat its first point at the end (that row gets the first tangent). Raises ValueError
    for NaN/inf, repeated consecutive points and cusps (the estimate vanishes), naming the
    row.
    """
    method = as_choice(method, "method", TANGENT_RULES)
    pts = as_points(points, "points")
    return _core.estimate_tangents(pts, as_bool(closed, "closed"), method)
