"""Moving frames along curves: the Python face of ``spinal._core`` (:func:`frames`,
:func:`closing_angle`, :func:`estimate_tangents`; :func:`frames_in_time` is in
``_frames_time``, the reading of the arguments in ``_frames_args``)."""


from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from . import _core, _merge
from ._frames_args import (
    METHODS,
    REFLECTIONS,
    TANGENT_RULES,
    _analytic,
    _cut_curves,
    _cut_rows,
    _guide_options,
    _orientation,
    _previous_twist_guide,
    _previous_weight,
    _sampled,
    _shape,
    _signed_by,
    _skipped_warning,
    _third,
)
from ._progress import Progress, Reported, checked
from ._steer import STEERING, steering
from ._types import (
    Array,
    Constraints,
    CurveBundle,
    Float64Array,
    FrameMethod,
    Ints,
    ProgressArg,
    Reflection,
    TangentRule,
)
from ._validate import (
    as_bool,
    as_choice,
    as_curves,
    as_out,
    as_points,
    as_turns,
    fill_out,
    is_curve_list,
)
from .curves import Curve

__all__ = ["closing_angle", "estimate_tangents", "frames"]


def _compute(points: object, tangents: object, method: object, initial: object, closed: object,
             end: object, turns: object, reflection: object, u: object, lengths: object,
             offsets: object, points_arg: str = "points", report: Reported | None = None,
             out: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, bool]:
    method = as_choice(method, "method", METHODS)
    reflection = as_choice(reflection, "reflection", REFLECTIONS)
    closed = as_bool(closed, "closed")
    turns = as_turns(turns, "turns")
    pts: np.ndarray | None
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
        d3 = _third(points, uu, method)
        out, angle = _core.frames_analytic(pts, uu, d1, d2, _shape(method, closed, iv, if_, ev, ef,
                                                                   turns=turns), d3)
        if report is not None:
            report(len(out), len(out))
        return out, np.array([angle]), False
    if u is not None:
        raise TypeError("u: only used with an analytic curve from spinal.curves")
    pts, tgs, offs, bundle = _sampled(points, tangents, reflection, lengths, offsets,
                                      points_arg)
    curves = offs.size - 1
    iv, if_ = _orientation(initial, "initial", curves, bundle)
    ev, ef = _orientation(end, "end", curves, bundle)
    # reflection="tangents": the chords of double reflection come from a quadrature of the
    # tangents (the core's `tangent_chords` flag)
    chords_from_tangents = reflection == "tangents"

    def run(p: np.ndarray | None, offs: np.ndarray, tgs: np.ndarray | None
            ) -> tuple[np.ndarray, np.ndarray]:
        # the rows as given are written straight into `out` (the rows kept after merging
        # repeats are spread over it by the caller)
        options = _shape(method, closed, iv, if_, ev, ef, tangent_chords=chords_from_tangents,
                         turns=turns, points_arg=points_arg)
        return _core.frames_sampled(p, tgs, offs, options, report, out if p is pts else None)

    if pts is None or chords_from_tangents:  # (the quadrature's grid is the rows as given)
        out, angles = run(pts, offs, tgs)
    else:  # consecutive repeated samples merged
        out, angles = _merge.on_rows(run, pts, offs, closed, bundle, (tgs,), points_arg)
    return out, angles, bundle


def _spine_frames(points: object, name: str, initial: object = None, closed: bool = False
                  ) -> np.ndarray:
    """The default frames of one curve passed to a spinal function as ``name`` (errors about
    the points name it)."""
    out, _, _ = _compute(points, None, "double_reflection", initial, closed, None, 0, "chord",
                         None, None, None, points_arg=name)
    res: np.ndarray = out
    return res


def frames(
    points: Array | Curve | CurveBundle | None,
    tangents: Array | CurveBundle | None = None,
    *,
    method: FrameMethod = "double_reflection",
    initial: Array | None = None,
    closed: bool = False,
    end: Array | None = None,
    turns: float = 0,
    reflection: Reflection = "chord",
    u: int | Array | None = None,
    lengths: Ints | None = None,
    offsets: Ints | None = None,
    constraints: Constraints | Sequence[Constraints | None] | None = None,
    twist_rule: Literal["arc_length", "min_angular_speed"] = "arc_length",
    guide: Array | None = None,
    guide_weight: float = 1.0,
    guide_tolerance: float = 1e-3,
    previous: Array | None = None,
    previous_twist: bool = False,
    previous_weight: float | None = None,
    guide_sign: Literal["follow", "free"] = "follow",
    on_invalid: Literal["raise", "skip"] = "raise",
    progress: ProgressArg = False,
    out: npt.NDArray[np.float64] | None = None,
) -> Float64Array:
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
        chord length, one-sided at open ends with the end tangents bounded by the turn of
        the last two chords, periodic when ``closed``), which keeps double
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
        * ``"bisector"``: Klok's projection for polygons given as points only (Klok 1986;
          Zheng's thesis §2.3): the tangent at a vertex is the normal of the plane through
          the bisector of its two segments, ``t_i ∝ d̂_{i−1} + d̂_i`` (the end segment's
          direction at an open end), and ``r`` is projected along each segment onto the next
          such plane. No twist on a planar polygon; 2nd order at the interior vertices of a
          sampled curve, 1st order at the ends. ``tangents`` are not accepted.
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
        * ``"rk4_phi"``: classical Runge–Kutta on the equivalent form ``r′ = −(r·t′) t``
          without projection, the variant whose errors Wang et al. (2008) tabulate (Table
          III); the frame written is the normal part of the state, normalised. Analytic
          curves only; 4th order, about 1.5× the error of ``"rk4"``. For comparisons.
        * ``"torsion"``: the Frenet frame turned about ``t`` by ``θ = −∫τ ds`` (Simpson's
          rule on ``τ|x′|`` with the exact ``x′, x″, x‴``; Wang et al. 2008 Eq. 3, Zheng's
          thesis §2.4), the RMF where the Frenet frame exists: exact on a circular helix,
          4th order in general. Analytic curves only; a curve whose curvature vanishes at a
          sample or midpoint is refused (the Frenet frame and the torsion are undefined
          there; near an inflection the torsion is unbounded). For comparisons.
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
        across the seam (up to a half turn for half-integer ``turns``; a repeated first
        point still gets the first frame). Linear in arc length is the minimiser of ``∫(κ² + α′²) ds`` (Wang et
        al. §6.3).
    end : array_like (3,) or (3, 3), optional
        A prescribed reference vector (or frame) at the last sample; the angle from the RMF to
        it (in (−π, π], plus ``2π·turns``) is distributed linearly in arc length, so the last
        frame meets it exactly.
    turns : int or float
        Extra turns added to the closing or end twist (``k`` in ``α + 2πk``, radians). A
        whole number (an int, or a float such as ``2.0``: the int's frames bit for bit), or,
        for the closing twist of a closed curve, a half number ``k = j + ½`` (``0.5``,
        ``-0.5``, ``1.5``): the total spread is then ``α + 2πk = α + π + 2πj``, so the last
        frame carried across the closing segment is the first one turned by π about the
        tangent (``r → −r``, ``s → −s``): the frames close up to a half turn. A profile that
        maps onto itself under that half turn still closes (``spinal.sweep(...,
        closed=True, turns=0.5)``; Ma 1996, Fig. G.1c, adds multiples of π to the twist of a
        closed ribbon for this reason; Zheng's eq. 7.3 takes ``2kπ``, whole turns).
        Half numbers work with ``twist_rule`` (the closing interval), ``guide`` (the guide
        followed up to the half turn across the seam) and ``previous`` (also in
        :func:`frames_in_time`); with ``end`` or ``constraints`` (met exactly, so whole turns
        between them) and per-interval counts they raise ValueError naming ``turns``, as do
        other fractions.
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
        use all cores too (a parallel prefix scan of the per-segment rotations). A bundle may
        also be given as users hold it: ``points`` a list (any sequence) of ``(n_i, 3)``
        arrays of any real dtype, e.g. nibabel's ``ArraySequence`` (``tangents`` likewise);
        the frames of all curves then come back to back in one array.
    constraints : mapping or (indices, vectors), optional
        Prescribed orientations anywhere along the curve: ``{row: vector or (3, 3) frame}``
        or a pair ``(indices (k,), vectors (k, 3) or frames (k, 3, 3))``; any number, interior
        rows included, negative rows count from the end. Vectors are projected onto the
        normal plane (an error if parallel to the tangent); a frame's ``t`` must agree with
        the tangent within 1e-3 rad. Every frame is the RMF turned about ``t`` by ``α``
        (``g = cos α r + sin α (t × r)``, Zheng 2008 §7.3); each constraint fixes ``α`` at its
        row exactly, and between consecutive constraints the twist ``wrap(a_{j+1} − a_j) +
        2π·turns`` (the least turn, plus ``turns`` whole turns per interval) is spread by
        ``twist_rule``. Before the first and after the last constraint of an open curve the
        frames are the RMF turned to meet the nearest constraint. ``initial``/``end`` are
        constraints at the first/last row; with ``end`` the first row is pinned to the start
        (``initial`` or the default), so ``end=v`` is ``constraints={0: start, -1: v}``. On a
        closed curve the intervals run round the seam (where the RMF's closing angle enters).
        With ``lengths``/``offsets``: a list with one entry per curve (a mapping, a pair or
        ``None``), rows local to each curve (0 is the curve's first row).
    twist_rule : {"arc_length", "min_angular_speed"}
        How the twist between constraints (and of ``end``/``closed``) is spread.
        ``"arc_length"`` (default): linear in arc length, the least total squared angular
        speed ``∫|ω|² ds = ∫(κ² + α′²) ds`` (Zheng eq. 7.8; Wang et al. §6.3 eq. 24).
        ``"min_angular_speed"``: the least total angular speed ``∫|ω| ds = ∫√(κ² + α′²) ds``
        (Zheng eq. 7.5–7.7; Wang et al. §6.3 eq. 21–23): ``α′ = Cκ``, the twist follows the curvature;
        discretely each segment takes the share ``θ_i / Σθ`` of its interval's twist,
        ``θ_i`` the angle between consecutive tangents (the exact minimiser of
        ``Σ √(θ_i² + Δα_i²)``); on an interval that does not turn it falls back to arc length.
    guide : array_like (n, 3) or (3,), optional
        Directions for ``r`` to follow (one per sample, or one for all, e.g. "up"): ``r``
        follows the guide's projection on the normal plane, at angle ``φ_i`` from the RMF,
        smoothed: ``α`` minimises ``Σ (h̄/h_i)(α_{i+1} − α_i)² + guide_weight · Σ w_i
        (μ_i/h̄)(α_i − φ_i)²`` (``h_i`` segment lengths, ``h̄`` their mean, ``μ_i`` the
        half-lengths at sample ``i``, ``w_i = sin²∠(g_i, t_i)``), a symmetric tridiagonal
        system solved in O(n) after unwrapping ``φ``. Where the guide is within
        ``guide_tolerance`` of ``±t`` it is ignored and the frame falls back to the RMF's
        twist rate. ``constraints``/``initial``/``end`` are met exactly on top.
    guide_weight : float
        Weight of the guide error against the twist rate, per sample (> 0): the frame follows
        the guide on features longer than about ``1/√guide_weight`` samples; the bias on a
        smooth guide is about ``φ″/guide_weight`` (``φ″`` per sample²).
    guide_tolerance : float
        Angle in radians (in [0, π/2)) from the tangent below which a guide vector is ignored.
    guide_sign : {"follow", "free"}
        ``"follow"`` (default): ``r`` follows each guide vector's direction. ``"free"``: each
        guide row is an axis (``g`` and ``−g`` alike, e.g. raw carbonyl bonds of a β-strand,
        which alternate): the guide angles ``φ_i`` are unwrapped modulo π instead of 2π, so
        ``r`` follows whichever of ``±g_i`` continues the frame (the first usable row keeps
        its sign), as molecular cartoon renderers flip alternate peptide planes. A closed
        curve still closes: axes that come back reversed after a round spread the half turn.
        With ``previous`` too, each row's sign is the one that agrees with the previous
        frames' ``r`` column (``g·r_prev ≥ 0``): the frames continue those of the previous
        time step rather than the first row's sign (a β-strand of an MD trajectory does not
        flip between steps); the signed guide is then followed alone. With ``"follow"``
        and ``previous``, the guide and the previous frames are two targets of one solve
        (see ``previous``).
    on_invalid : {"raise", "skip"}
        What to do with curves (of a bundle, or the one curve) that hold a NaN or an
        infinity or have fewer than 2 (closed: 3) distinct points: refuse them (ValueError
        naming the curve and row) or leave them out, with a :class:`SkippedCurvesWarning`
        naming them (its ``curves``), their rows NaN in the result (the other curves'
        frames are those of the call without them). Not with ``constraints``.
    progress : bool or callable
        Report the rows done (those of the curves done, in any order): ``True`` shows a bar
        (tqdm when installed, in a terminal or a notebook) or a line on stderr at every
        tenth; a callable is called as ``progress(rows_done, rows)`` from the calling
        thread, about every 20 ms while the count moves and once at the end. The work only
        counts (the same frames, bit for bit). With ``constraints``, ``guide``,
        ``previous``, ``twist_rule`` or per-interval ``turns``, one report at the end.
    previous : array_like (n, 3, 3), optional
        The frames of the same curve at the previous time step (same sample count): the
        result is the RMF (with any ``closed`` twist) turned by the one angle that brings it
        closest to ``previous`` (see :func:`frames_in_time`), so frames of a moving curve do
        not flicker. Not with ``initial``, ``end`` or ``constraints``, which fix the start
        themselves. With a ``guide`` (``guide_sign="follow"``) the guide and the previous
        ``r`` columns ``p_i`` are two soft targets of one twist solve: ``α`` minimises
        ``Σ (h̄/h_i)(α_{i+1} − α_i)² + Σ (μ_i/h̄)[guide_weight · w_i (α_i − φ_i)²
        + previous_weight · v_i (α_i − ψ_i)²]``, ``ψ_i`` the angle of ``p_i``'s projection
        from the RMF and ``v_i = sin²∠(p_i, t_i)`` (both angles unwrapped along the samples,
        ``ψ`` by whole turns to within π of ``φ`` at the first sample with both). Each row's
        two terms are one term at the weighted mean angle ``(c_g φ_i + c_p ψ_i)/(c_g + c_p)``
        with the summed weight; so a guide that agrees with the previous frames acts with
        ``guide_weight + previous_weight``, and as either weight goes to 0 the frames tend
        (linearly in it) to those of the other target alone. ``previous_twist`` does not
        change this.
    previous_twist : bool
        With ``previous``: follow its twist profile too, not only its start: the frames are
        those of ``guide=previous[:, :, 0]`` (the previous ``r`` columns, projected on the new
        normal planes and smoothed by ``previous_weight`` as ``guide`` by ``guide_weight``;
        ``guide_tolerance`` applies), so a twist the previous frames carried along the curve is kept. On a curve
        that does not move, the previous frames come back up to the guide's smoothing bias
        (about ``φ″/guide_weight``, ``φ″`` the previous twist's second difference per
        sample). Default ``False``: the RMF turned by one angle.
    previous_weight : float, optional
        The weight of the previous frames' ``r`` against the twist rate, per sample (> 0),
        with ``previous_twist`` or with a ``guide`` (see ``previous``). Default: the value of
        ``guide_weight``.
    out : ndarray (n, 3, 3) float64, optional
        An array to write the frames into (and return), for callers that reuse one buffer
        across animation frames: exactly the result's shape and dtype float64, C-contiguous
        and writeable, sharing no memory with an input (else a ValueError naming ``out``).
        The frames are those of the call without ``out``, bit for bit; the usual calls
        (sampled curves without ``constraints``, ``guide``, ``previous``, repeated samples
        or skipped curves) write them there directly, the others copy them in. If the call
        raises (or is interrupted by Ctrl-C), the contents of ``out`` are unspecified.

    Returns
    -------
    ndarray (n, 3, 3) float64
        One frame per input row (``out`` itself when given).

    Raises
    ------
    TypeError
        Non-numeric input, wrong argument types.
    ValueError
        Wrong shapes, fewer than 2 distinct points (3 for a closed curve), NaN/inf, zero
        tangents, a segment whose chord runs against given ``tangents``
        (``(x_{i+1} − x_i)·(t_i + t_{i+1}) ≤ 0``; estimated tangents never do short of two
        reversals in a row, see :func:`estimate_tangents`), an
        ``initial``/``end`` vector parallel to the tangent,
        a constraint row out of range or a constraint parallel to its tangent, a ``guide`` or
        ``previous`` of the wrong shape, two constraints on samples merged into one. The
        message names the argument and the row (as given).

    Consecutive samples closer than ``2⁻⁴⁰ ≈ 9.1e-13`` times the curve's size are one point:
    the frames are computed on the curve without the repeats, whose rows get the frame of
    the row they repeat (a per-row ``tangents``, ``guide`` or ``previous`` is cut alike; a
    constraint on a repeat applies to the row it repeats). Not with ``reflection="tangents"``
    (its quadrature needs the rows as given) or an analytic curve, where repeats raise.

    Examples
    --------
    >>> import numpy as np, spinal
    >>> u = np.linspace(0, 4 * np.pi, 200)
    >>> F = spinal.frames(np.c_[np.cos(u), np.sin(u), 0.2 * u])
    >>> F.shape
    (200, 3, 3)
    """
    on_invalid = as_choice(on_invalid, "on_invalid", ("raise", "skip"))
    progress = checked(progress)
    out = as_out(out, [("points", points), ("tangents", tangents), ("initial", initial),
                       ("end", end), ("guide", guide), ("previous", previous),
                       ("constraints", constraints), ("u", u), ("lengths", lengths),
                       ("offsets", offsets)])
    if on_invalid == "skip" and not isinstance(points, Curve):
        cut = _merge.invalid_curves(points, lengths, offsets, as_bool(closed, "closed"))
        if cut is not None:
            if constraints is not None:
                raise TypeError("on_invalid: 'skip' does not take constraints= (their rows "
                                "would move); leave the invalid curves out first")
            pts, offs, keep, kept, bad, nan, few = cut
            _skipped_warning(nan, few, closed, "their frames are NaN")
            res = np.full((len(pts), 3, 3), np.nan)
            if kept[-1]:
                n, c = len(pts), len(offs) - 1
                res[keep] = frames(
                    pts[keep], _cut_rows(tangents, keep, n), method=method,
                    initial=_cut_curves(initial, bad, c), closed=closed,
                    end=_cut_curves(end, bad, c), turns=turns, reflection=reflection,
                    offsets=kept, twist_rule=twist_rule, guide=_cut_rows(guide, keep, n),
                    guide_weight=guide_weight, guide_tolerance=guide_tolerance,
                    previous=_cut_rows(previous, keep, n), previous_twist=previous_twist,
                    previous_weight=previous_weight, guide_sign=guide_sign, progress=progress)
            return fill_out(out, res)
    previous_twist = as_bool(previous_twist, "previous_twist")
    guide_weight, guide_tolerance = _guide_options(guide_weight, guide_tolerance)
    previous_weight = _previous_weight(previous_weight, guide_weight)
    if previous_twist and previous is None:
        raise TypeError("previous_twist: needs previous (the frames whose twist to follow)")
    guide_sign = as_choice(guide_sign, "guide_sign", ("follow", "free"))
    if (constraints is not None or guide is not None or previous is not None
            or twist_rule != "arc_length" or isinstance(turns, (list, tuple, np.ndarray))):
        res = _steered(points, tangents, method, initial, closed, end, turns, reflection, u,
                       lengths, offsets, constraints, twist_rule, guide, guide_weight,
                       guide_tolerance, previous, previous_twist, guide_sign, previous_weight)
        with Progress(progress, len(res), "frames", "row") as bar:
            bar.update(len(res))
        return fill_out(out, res)
    with Reported(progress, "frames", "row") as report:
        res, _, _ = _compute(points, tangents, method, initial, closed, end, turns, reflection,
                             u, lengths, offsets, report=report.callback, out=out)
    return fill_out(out, res)


def closing_angle(
    points: Array | Curve | CurveBundle | None,
    tangents: Array | CurveBundle | None = None,
    *,
    method: FrameMethod = "double_reflection",
    reflection: Reflection = "chord",
    u: int | Array | None = None,
    lengths: Ints | None = None,
    offsets: Ints | None = None,
) -> float | Float64Array:
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


def estimate_tangents(
    points: Array | CurveBundle,
    *,
    closed: bool = False,
    method: TangentRule = "five_point_bounded",
    lengths: Ints | None = None,
    offsets: Ints | None = None,
    on_invalid: Literal["raise", "skip"] = "raise",
) -> Float64Array:
    r"""Unit tangents estimated from sampled points, ``(n, 3)``.

    * ``"five_point_bounded"`` (default): ``"five_point"`` below, with each open end tangent
      bounded by the turn of the last two chords: with ``ĉ`` the end chord and ``φ`` its
      angle to the neighbouring chord (``φ ≈ κh``), an end tangent leaning more than ``α``
      from ``ĉ`` is turned towards ``ĉ`` onto the cone ``∠(t, ĉ) = α`` (in the plane of
      ``ĉ`` and ``t``), where ``α = φ/2`` on coarse samplings (``φ ≥ 20°``), ``α = φ`` on
      fine ones (``φ ≤ 10°``), a smoothstep between, and never more than 45°. On smooth
      samplings the exact end tangent leans ``κh/2 + O(h²)`` from the end chord (half the
      turn only to first order), inside the whole-turn cone, so the estimate stays O(h⁴)
      there; on coarse samplings (e.g. 20-point streamlines) the one-sided quartic
      extrapolates the last bends and can lean far past the end chord (chisel-shaped tube
      ends), which the half-turn bound removes. Where the end chords turn by more
      than 30° (an end corner), the result is then blended towards ``ĉ`` with the corner
      weight of the chord guard below: from 60° on the end tangent is the end chord, and a
      tube's end is cut square to it. The circle rule's end tangent (3 or 4 points) is
      bounded alike. Interior and closed-curve tangents are those of ``"five_point"``.
    * ``"five_point"``: the derivative at ``x_i`` of the quartic through the five
      samples around it (one-sided at open ends, periodic when ``closed``), parameterised by
      cumulative chord length (Lagrange weights by Fornberg's algorithm). For equal chords
      these are the 5-point formulas of Wang et al. (2008, §6.1),
      ``x_{i−2} − 8x_{i−1} + 8x_{i+1} − x_{i+2}``; for unequal spacing the direction stays
      O(h⁴) accurate and straight runs give the exact direction. Double reflection with these
      tangents is 4th order. At an open end whose first chord is much longer than the next
      ones the one-sided quartic would extrapolate from a distant cluster and amplify the
      rounding of the samples ~(H/h)³ times; there the farthest samples are dropped (cubic,
      quadratic, then the end chord) until the amplification is at most 10³ (equal chords:
      15), which leaves end chords up to about 7.5× their neighbours at the quartic. Where
      the estimate turns more than 60° away from the ``"circle"`` estimate (at a kink next
      to very uneven chords the quartic can swing round and point backwards), the circle
      estimate is used; on smooth samplings the two agree to O(h²), so this never triggers
      there.
    * ``"five_point_uniform"``: the paper's stencils with the sample index as parameter:
      O(h⁴) only if the samples come from a uniform step of a smooth parameterisation
      (kept to reproduce the paper; it can point backwards on very uneven spacing).
    * ``"circle"``: the tangent of the circle through each point and its two neighbours,
      ``|b|² a + |a|² b`` with ``a = x_i − x_{i−1}``, ``b = x_{i+1} − x_i`` (Zheng 2008 §7.1,
      whose printed weights ``|b| a + |a| b`` are exact only for equal chords); exact on
      circles for any spacing (with turns under 30° per sample, see below), O(h²) in general.

    Every rule ends with a chord guard, so that tangents exist on any polyline and tubes
    keep their cross-section through its corners. With ``p̂, q̂`` the unit chords at a sample,
    ``φ`` the turn between them and ``b̂`` their bisector (the tangent of a corner: the
    straight tubes about the two chords meet in its normal plane):

    1. where the chords turn by more than 30° (fewer than 12 samples per turn of a circle),
       the estimate is blended towards ``b̂``, ``t = normalise((1 − w) t₀ + w b̂)`` with ``w``
       the smoothstep ``3s² − 2s³`` of ``s = (cos 30° − cos φ)/(cos 30° − cos 60°)`` clamped
       to [0, 1]: the bisector itself from 60° on;
    2. where the result still points more than about 60° away from a chord (margin
       ``m = min(t·p̂, t·q̂) / cos(φ/2)`` below 1/2; 1 for the bisector), it is blended
       towards ``b̂`` with ``w = min(1, 1 − 2m)``, which leaves a margin of at least
       ``cos(φ/2)/2`` against both chords.

    Both steps are continuous in the points, short of reversals: where the chords turn back
    to within 10⁻⁶ rad of 180°, the bisector is rounding noise and the tangent is normal to
    the chord instead. Then every segment runs along the tangents at its ends
    (``(x_{i+1} − x_i)·(t_i + t_{i+1}) > 0``) unless both of its ends reverse. Samplings that turn by less than 30° per sample with
    estimates within 60° of both chords (any reasonably sampled smooth curve) are never
    touched, so the orders above hold there. The unbounded rules' open end tangents
    (``"five_point"``, ``"five_point_uniform"``) are left as their stencils give them.

    With 3–4 points the circle rule is used, with 2 points the chord. A closed curve may
    repeat its first point at the end (that row gets the first tangent). ``lengths`` /
    ``offsets``: many curves back to back, as in :func:`frames` (each curve estimated on
    its own, in parallel; ``closed`` applies to every curve); ``points`` may also be a list
    (any sequence) of ``(n_i, 3)`` arrays, e.g. nibabel's ``ArraySequence``, whose tangents
    come back to back in one array. Consecutive samples closer than ``2⁻⁴⁰`` of the curve's
    size are merged: their rows get the tangent of the row they repeat. Raises ValueError
    for NaN/inf and for curves with fewer than 2 distinct points (3 closed), naming the row
    (and the curve, in a bundle); ``on_invalid="skip"`` leaves such curves out instead,
    with a :class:`SkippedCurvesWarning` naming them, and their rows NaN.
    """
    method = as_choice(method, "method", TANGENT_RULES)
    closed = as_bool(closed, "closed")
    if as_choice(on_invalid, "on_invalid", ("raise", "skip")) == "skip":
        cut = _merge.invalid_curves(points, lengths, offsets, closed)
        if cut is not None:
            pts, _, keep, kept, _, nan, few = cut
            _skipped_warning(nan, few, closed, "their tangents are NaN")
            out = np.full((len(pts), 3), np.nan)
            if kept[-1]:
                out[keep] = estimate_tangents(pts[keep], closed=closed, method=method,
                                              offsets=kept)
            return out
    if not is_curve_list(points) and lengths is None and offsets is None:
        pts = as_points(points, "points")
        offs, bundle = np.array([0, len(pts)], dtype=np.int64), False

        def run(pts: np.ndarray, offs: np.ndarray) -> np.ndarray:
            return _core.estimate_tangents(pts, closed, method)
    else:
        pts, offs, bundle = as_curves(points, lengths, offsets)

        def run(pts: np.ndarray, offs: np.ndarray) -> np.ndarray:
            return _core.estimate_tangents(pts, closed, method, offs)
    # consecutive repeated samples merged (they get the tangent of the row they join)
    res: Float64Array = _merge.on_rows(run, pts, offs, closed, bundle)
    return res


def _steered(points: object, tangents: object, method: object, initial: object, closed: object,
             end: object, turns: object, reflection: object, u: object, lengths: object,
             offsets: object, constraints: object, twist_rule: object, guide: object,
             guide_weight: float, guide_tolerance: float, previous: object,
             previous_twist: bool = False, guide_sign: str = "follow",
             previous_weight: float | None = None) -> np.ndarray:
    """:func:`frames` with its steering arguments (``constraints``, ``twist_rule``,
    ``guide``, ``previous`` or per-interval ``turns``)."""
    method = as_choice(method, "method", METHODS)
    previous_weight = guide_weight if previous_weight is None else previous_weight
    with_guide = guide is not None and previous is not None
    free = as_choice(guide_sign, "guide_sign", ("follow", "free")) == "free"
    # an axis guide with the previous step's frames: previous picks each row's sign
    signed_by_previous = with_guide and free
    # a direction guide with the previous step's frames: two targets of one twist solve
    targets = with_guide and not free
    if previous_twist or targets:
        if method == "frenet":
            raise ValueError("previous: is not used by method='frenet': the Frenet frame is "
                             "fixed by the curve")
        for other, val in (("constraints", constraints),
                           ("guide", None if with_guide else guide),
                           ("initial", initial), ("end", end)):
            if val is not None:
                raise ValueError(f"previous: cannot be combined with {other} (they fix the "
                                 f"frames that previous would choose)")
    reflection = as_choice(reflection, "reflection", REFLECTIONS)
    closed = as_bool(closed, "closed")
    d1 = d2 = d3 = uu = tgs = None
    pts: np.ndarray | None
    if isinstance(points, Curve):
        if tangents is not None:
            raise TypeError("tangents: not accepted with an analytic curve (its exact tangents "
                            "are used)")
        if lengths is not None or offsets is not None:
            raise TypeError("lengths, offsets: not accepted with an analytic curve")
        if reflection != "chord":
            raise ValueError("reflection: 'tangents' applies to sampled curves only")
        pts, uu, d1, d2 = _analytic(points, u)
        d3 = _third(points, uu, method)
    else:
        if u is not None:
            raise TypeError("u: only used with an analytic curve from spinal.curves")
        pts, tgs, offs, bundle = _sampled(points, tangents, reflection, lengths, offsets)
    ref = pts if pts is not None else tgs
    assert ref is not None  # (_sampled refuses neither)
    rows = ref.shape[0]
    if uu is not None:
        offs, bundle = np.array([0, rows], dtype=np.int64), False
    curves = offs.size - 1
    iv, if_ = _orientation(initial, "initial", curves, bundle)
    ev, ef = _orientation(end, "end", curves, bundle)
    if bundle and (offs[0] != 0 or offs[-1] != rows or np.any(np.diff(offs) < 0)):
        # the core names the rule that the lengths/offsets break
        _core.frames_sampled(pts, tgs, offs, _shape(method, closed, turns=0))
    before = None
    if signed_by_previous:
        guide, previous, guide_sign = _signed_by(guide, previous, rows), None, "follow"
    elif targets:
        before, previous = _previous_twist_guide(previous, rows), None
    elif previous_twist:
        guide, previous = _previous_twist_guide(previous, rows), None
        guide_weight = previous_weight
    steer = steering(constraints, twist_rule, turns, guide, guide_weight, guide_tolerance,
                     previous, offs, bundle, rows, guide_sign, before, previous_weight)

    def run(pts: np.ndarray | None, tgs: np.ndarray | None, offs: np.ndarray,
            steer: Sequence[object]) -> np.ndarray:
        options = _shape(method, closed, iv, if_, ev, ef, tangent_chords=reflection == "tangents",
                         u=uu, d1=d1, d2=d2, d3=d3)
        return _core.frames_steered(pts, tgs, offs, options, dict(zip(STEERING, steer)))

    if pts is None or uu is not None or reflection == "tangents":
        return run(pts, tgs, offs, steer)
    try:
        return run(pts, tgs, offs, steer)
    except _core.RepeatedPointsError as exc:
        p = _merge.plan(pts, offs, closed)
        err = _merge.too_few_error(p, offs, closed, bundle)
        if err is not None:
            raise err from None
        if not p.merged:
            raise ValueError(str(exc)) from None
    return _steered_merged(run, p, pts, tgs, offs, steer, rows)


def _steered_merged(run: Callable[..., np.ndarray], p: _merge.Plan, pts: np.ndarray,
                    tgs: np.ndarray | None, offs: np.ndarray, steer: Sequence[Any],
                    rows: int) -> np.ndarray:
    """The steered frames on the rows that ``p`` keeps (a per-row guide and previous cut
    alike, constraint rows moved to the sample they merge into), spread back over the rows
    as given."""
    # turns, 5 constraint arrays, rule, guide, weight, tolerance, axis, prev, the previous
    # frames' r as a second target of the guide, its weight
    steer = list(steer)

    def cut(a: np.ndarray | None) -> np.ndarray | None:
        return None if a is None else np.ascontiguousarray(a[p.keep])

    if steer[7] is not None and len(steer[7]) == rows:
        steer[7] = cut(steer[7])
    steer[11] = cut(steer[11])
    steer[12] = cut(steer[12])
    cc, cr = steer[1], steer[2]
    if cr.size:
        kept = p.rows[offs[cc] + cr] - p.offsets[cc]
        key = cc * (rows + 1) + kept
        if np.unique(key).size < key.size:
            dup = np.flatnonzero(np.r_[False, np.diff(np.sort(key)) == 0])[0]
            c = int(np.sort(cc)[dup])
            raise ValueError(f"constraints: two constraints of curve {c} fall on one sample "
                             f"(rows that repeat a point are merged into the first); keep one")
        steer[2] = np.ascontiguousarray(kept, dtype=np.int64)
    try:
        out = run(cut(pts), cut(tgs), p.offsets, steer)
    except ValueError as exc:
        raise ValueError(_merge.as_given(str(exc), p, offs)) from None
    res: np.ndarray = out[p.rows]
    return res
