r"""Fleshing: spine-driven deformation with local volume preservation (Zhuo 2014).

A shape bound to a spine follows the spine's new pose and every small piece keeps its
volume: the offset from the spine is corrected with the curvature-based offset distance of
Wei Zhuo's dissertation ("Spine-based deformation with local volume preservation", Georgia
Tech 2014; Zhuo & Rossignac, CGF 32(2) 2013). See :class:`SpineBinding` and :func:`flesh`.
"""

from __future__ import annotations

import warnings
from typing import Literal, overload

import numpy as np

from . import _core, _motion
from ._flesh_roll import _given_roll, _posed_initial, _roll_to
from ._frames import _spine_frames
from ._mesh import FoldOverWarning
from ._types import Array, Float64Array, Int64Array, ProgressArg, SpineSolution
from ._validate import as_bool, as_choice, as_float_array, as_real

SOLUTIONS: tuple[SpineSolution, ...] = ("radial", "normal", "binormal", "blend", "none")


def _spine(x: Array, name: str, closed: bool = False) -> tuple[np.ndarray, int]:
    """A spine as ``(n, 3)`` rows and its width (2 or 3); a loop (``closed``) loses a repeated
    first point at its end."""
    arr = as_float_array(x, name)
    if arr.ndim != 2 or arr.shape[1] not in (2, 3):
        raise ValueError(f"{name}: expected an array of shape (n, 3) or (n, 2), got {arr.shape}")
    if arr.shape[0] < 2:
        raise ValueError(f"{name}: need at least 2 points, got {arr.shape[0]}")
    bad = np.flatnonzero(~np.isfinite(arr).all(axis=1))
    if bad.size:
        raise ValueError(f"{name}: row {bad[0]} is not finite")
    dim = arr.shape[1]
    if dim == 2:
        arr = np.c_[arr, np.zeros(len(arr))]
    arr = np.ascontiguousarray(arr)
    tol = 1e-12 * _scale(arr)
    if closed and len(arr) > 1 and float(_norms((arr[-1] - arr[0])[None])[0]) <= tol:
        arr = arr[:-1]
    if closed and len(arr) < 3:
        raise ValueError(f"{name}: a closed spine needs at least 3 distinct points, got "
                         f"{len(arr)}")
    rep = np.flatnonzero(_norms(np.diff(arr, axis=0)) <= tol)
    if rep.size:
        raise ValueError(f"{name}: rows {rep[0]} and {rep[0] + 1} repeat the same point")
    return arr, dim


def _loop(a: np.ndarray, closed: bool) -> np.ndarray:
    """Rows of a loop with the first repeated at the end (the core's closing edge)."""
    return np.ascontiguousarray(np.concatenate([a, a[:1]])) if closed else a


def _resample_loop(posed: np.ndarray, rest_arc: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A closed posed spine resampled at the rest samples' fractions of the loop's length
    (chord-length parameter): ``(n, 3)`` points and their positions ``k + u`` on the posed
    loop's edges (edge ``k`` from row ``k`` to row ``k + 1 mod m``). A loop cannot keep every
    edge length when its length changes, so the stretch ``λ = L1/L0`` is spread uniformly."""
    ring = np.concatenate([posed, posed[:1]])
    s = _arc(ring)
    target = rest_arc[:-1] / rest_arc[-1] * s[-1]
    k = np.clip(np.searchsorted(s, target, side="right") - 1, 0, len(posed) - 1)
    u = (target - s[k]) / (s[k + 1] - s[k])
    pts = ring[k] + u[:, None] * (ring[k + 1] - ring[k])
    return np.ascontiguousarray(pts), k + u


def _scale(a: np.ndarray) -> float:
    return max(float(np.abs(a).max(initial=0.0)), 1e-300)


def _norms(d: np.ndarray) -> np.ndarray:
    """Row lengths without overflow or underflow in the squares (hypot)."""
    out: np.ndarray = np.hypot(np.hypot(d[:, 0], d[:, 1]), d[:, 2])
    return out


def _arc(points: np.ndarray) -> np.ndarray:
    out: np.ndarray = np.r_[0.0, np.cumsum(_norms(np.diff(points, axis=0)))]
    return out


def _resample(posed: np.ndarray, chords: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Compass walk (our reading of Zhuo 2014 Ch. IV's "distance between consecutive samples" as
    the chord, not the arc length): points on the posed polyline, from its start, whose
    consecutive distances are the rest spine's chords ``chords``; past its end, along its
    last edge. Edge lengths are kept exactly, so the discrete stretch is 1 at the samples.
    Also returns each point's position ``k + u`` on the polyline (edge ``k``, fraction ``u``)."""
    return _core.flesh_resample(posed, np.ascontiguousarray(chords, dtype=np.float64))


def _vertices(vertices: Array, dim: int) -> np.ndarray:
    """``(V, dim)`` vertices as ``(V, 3)`` (the planar case gets z = 0)."""
    v = as_float_array(vertices, "vertices")
    if v.ndim != 2 or v.shape[1] != dim:
        raise ValueError(
            f"vertices: expected shape (V, {dim}) like rest_spine's columns, got {v.shape}"
        )
    if dim == 2:
        v = np.c_[v, np.zeros(len(v))]
    return np.ascontiguousarray(v, dtype=np.float64)


def _rest_frames(rest: np.ndarray, dim: int, closed: bool = False) -> np.ndarray:
    """The RMF of the rest spine; in the plane started with ``r`` in the plane (so the
    binormal stays out of it); on a loop with its closing angle spread in arc length."""
    if dim == 2:
        t0 = rest[1] - rest[0]
        return _spine_frames(rest, "rest_spine", initial=np.array([-t0[1], t0[0], 0.0]),
                             closed=closed)
    return _spine_frames(rest, "rest_spine", closed=closed)


class SpineBinding:
    r"""A shape registered on a rest spine, to be posed many times (Zhuo 2014, §1.1).

    Registration finds for every vertex the cross-section of the rest spine it lies in: the
    spine runs through the samples ``rest_spine``, with the unit tangents ``t_k`` and
    reference vectors ``r`` of :func:`spinal.frames` (a rotation-minimising frame) at the
    samples. Between samples ``k`` and ``k + 1`` the position ``C(a)``, ``a ∈ [0, 1]``, is the
    cubic Hermite interpolant of the two samples with end slopes ``h t_k`` and ``h t_{k+1}``
    (``h`` the chord length); the tangent is a normalised cubic Hermite interpolation of the
    sample tangents matching the sample curvatures (so sections turn smoothly and the map
    is continuous across samples); ``r`` is the blend of ``r_k`` and ``r_{k+1}`` (carried back
    to ``t_k``) in the normal plane of ``t_k``, carried to the interpolated tangent by the
    minimal rotation. The cross-section at edge ``k``, parameter ``a`` is the plane through
    ``C(a)`` normal to the interpolated tangent. A vertex is bound to the nearest such
    point (the closest point of the interpolated spine with smoothly turning sections, never
    the nearest sample) and keeps its offset in the interpolated frame. Points past the
    spine's ends use the straight extension of the end.

    Parameters
    ----------
    vertices : array_like (V, 3) or (V, 2)
        The shape (any real dtype; never modified). 2-column input is the planar case
        (``rest_spine`` must then have 2 columns too).
    rest_spine : array_like (n, 3) or (n, 2)
        Rest spine samples, n ≥ 2, no repeated consecutive points, sampled finely enough that
        the tangent turns less than 90° between samples.
    closed : bool
        The spine is a loop (rings, tentacle loops; n ≥ 3, a repeated first point at the end
        is accepted): the closing edge from the last sample to the first carries sections
        like the others, there are no ends to extend, and the frames are those of
        ``spinal.frames(rest_spine, closed=True)`` (the RMF with its closing angle spread
        linearly in arc length, Wang et al. §6.3), so the sections meet across the seam.
        The posed spines of :meth:`deform` are loops too.

    Attributes
    ----------
    edge : ndarray (V,) int64 — the spine edge of every vertex.
    param : ndarray (V,) float64 — the parameter ``a ∈ [0, 1]`` on that edge.
    arc_length : ndarray (V,) float64 — the rest arc length of the section (past the ends: of
        the end), in the units of the input.
    offset : ndarray (V, 2) float64 — the offset in the rest frame's ``(r, s)`` columns.

    Raises
    ------
    ValueError / TypeError
        Messages start with the argument's name: wrong shapes, NaN/inf, repeated spine points.
    """

    clamped: Int64Array

    def __init__(self, vertices: Array, rest_spine: Array, *, closed: bool = False) -> None:
        closed = as_bool(closed, "closed")
        rest, dim = _spine(rest_spine, "rest_spine", closed)
        v = _vertices(vertices, dim)
        self._closed = closed
        self._frames = _rest_frames(rest, dim, closed)
        self._dim = dim
        self._rest = rest
        self._lengths = _arc(_loop(rest, closed))
        self._edge, self._coords = _core.flesh_bind(
            _loop(rest, closed), _loop(self._frames, closed), v, closed
        )
        self.clamped = np.zeros(0, dtype=np.int64)

    def __len__(self) -> int:
        return len(self._edge)

    @property
    def edge(self) -> Int64Array:
        """``(V,)`` int64: the rest spine edge ``k`` (between samples ``k`` and ``k + 1``) that
        holds each vertex's cross-section; ``0`` or ``n − 2`` for vertices past the ends. On a
        closed spine edge ``n − 1`` is the closing edge (from sample ``n − 1`` to sample 0)."""
        return self._edge.copy()

    @property
    def rest_frames(self) -> Float64Array:
        """``(n, 3, 3)`` float64: the rest spine's frames (columns ``r, s, t``) in which the
        offsets are stored. A rigid motion ``x ↦ Rx + c`` of the whole shape is the pose
        ``deform(rest_spine @ R.T + c, posed_frames=R @ rest_frames)``."""
        return self._frames.copy()

    @property
    def param(self) -> Float64Array:
        """``(V,)`` float64: the parameter ``a ∈ [0, 1]`` of the section on its edge
        (dimensionless; the section's spine point is the cubic Hermite ``C(a)`` between ``R_k``
        and ``R_{k+1}``, see the class notes). Vertices past
        the spine's ends get ``a = 0`` on the first edge or ``a = 1`` on the last."""
        return self._coords[:, 0].copy()

    @property
    def arc_length(self) -> Float64Array:
        """``(V,)`` float64: rest arc length ``S_k + a (S_{k+1} − S_k)`` of each vertex's
        section along the rest polyline (``S_k`` the cumulative chord lengths), in the units of
        the input; ``0`` or the total length past the ends."""
        k = self._edge
        s = self._lengths
        out: Float64Array = s[k] + self._coords[:, 0] * (s[k + 1] - s[k])
        return out

    @property
    def offset(self) -> Float64Array:
        """``(V, 2)`` float64: each vertex's offset from the spine in its section, as
        coordinates along the ``r`` and ``s`` columns of the interpolated rest frame (units of
        the input; in the planar case ``s`` is out of the plane, so the second column is 0)."""
        return self._coords[:, 2:4].copy()

    def posed_spine(self, posed_spine: Array, *, stretchable: bool = False) -> Float64Array:
        """The posed spine as used by :meth:`deform`: ``(n, 3)`` (resampled when not
        stretchable)."""
        out: Float64Array = self._posed(posed_spine, stretchable)[0]
        return out

    def _posed(self, posed_spine: Array, stretchable: bool, slide: float = 0.0
               ) -> tuple[np.ndarray, int, np.ndarray]:
        """The posed spine as used, the caller's row count ``m`` and the positions ``k + u``
        of the used samples on the caller's polyline (edge ``k``, fraction ``u``)."""
        posed, dim = _spine(posed_spine, "posed_spine", self._closed)
        if dim != self._dim:
            raise ValueError(f"posed_spine: expected {self._dim} columns like rest_spine")
        m = len(posed)
        if slide != 0.0:
            if as_bool(stretchable, "stretchable"):
                raise TypeError("slide: not with stretchable=True (each posed sample carries "
                                "the sections of its rest sample)")
            q, back = _motion.slid(posed, slide, self._closed)
            pts, at = (_resample_loop(q, self._lengths) if self._closed
                       else _resample(q, np.diff(self._lengths)))
            return pts, m, _motion.positions(at, q, back, posed, self._closed)
        if as_bool(stretchable, "stretchable"):
            if m != len(self._rest):
                raise ValueError(
                    f"posed_spine: a stretchable spine needs the rest spine's {len(self._rest)} "
                    f"samples (the sample index is the shared parameter), got {m}"
                )
            return posed, m, np.arange(m, dtype=np.float64)
        if self._closed:
            pts, at = _resample_loop(posed, self._lengths)
            return pts, m, at
        pts, at = _resample(posed, np.diff(self._lengths))
        return pts, m, at

    @overload
    def deform(
        self,
        posed_spine: Array,
        *,
        solution: SpineSolution = "radial",
        blend: float | None = None,
        stretchable: bool = False,
        twist: float | Array | None = None,
        strict: bool = False,
        return_clamped: Literal[False] = False,
        posed_frames: Array | None = None,
        posed_up: Array | None = None,
        slide: float = 0.0,
    ) -> Float64Array: ...
    @overload
    def deform(
        self,
        posed_spine: Array,
        *,
        solution: SpineSolution = "radial",
        blend: float | None = None,
        stretchable: bool = False,
        twist: float | Array | None = None,
        strict: bool = False,
        return_clamped: Literal[True],
        posed_frames: Array | None = None,
        posed_up: Array | None = None,
        slide: float = 0.0,
    ) -> tuple[Float64Array, Int64Array]: ...
    @overload
    def deform(
        self,
        posed_spine: Array,
        *,
        solution: SpineSolution = "radial",
        blend: float | None = None,
        stretchable: bool = False,
        twist: float | Array | None = None,
        strict: bool = False,
        return_clamped: bool = False,
        posed_frames: Array | None = None,
        posed_up: Array | None = None,
        slide: float = 0.0,
    ) -> Float64Array | tuple[Float64Array, Int64Array]: ...
    def deform(
        self,
        posed_spine: Array,
        *,
        solution: SpineSolution = "radial",
        blend: float | None = None,
        stretchable: bool = False,
        twist: float | Array | None = None,
        strict: bool = False,
        return_clamped: bool = False,
        posed_frames: Array | None = None,
        posed_up: Array | None = None,
        slide: float = 0.0,
    ) -> Float64Array | tuple[Float64Array, Int64Array]:
        r"""The shape posed on ``posed_spine`` with its volume preserved locally.

        Every vertex is rebuilt from the posed spine at its registered parameter by
        unbending (rest curvature), transfer (rest frame → posed frame, then ``twist``) and
        bending (posed curvature) — Zhuo 2014 §4.2, §5.2 — with the offset correction of
        ``solution``:

        ``"radial"`` (default)
            distance ``r`` from the spine corrected, direction kept: unbend
            ``r* = r0 √(1 − ⅔κ0 r0 cosθ0)``, bend ``r1²(1 − ⅔κ1 r1 cosθ1) = r*²/λ`` (cubic).
        ``"normal"``
            coordinate ``x`` along the principal normal: ``x − ½κx²`` is carried over
            (quadratic; the planar solution, Eq. 2/7).
        ``"binormal"``
            coordinate ``y`` along the binormal: ``(1 − κx) y`` is carried over (linear).
        ``"blend"``
            between the two, with the weight ``blend = w ∈ [0, 1]`` of the normal solution
            (``w = 1`` is ``"normal"``, ``w = 0`` is ``"binormal"``). Zhuo's Ch. VIII shows
            that treating the two coordinates as independent (Eq. 44,
            ``(x1 − ½κ1x1²) y1 = (x0 − ½κ0x0²) y0``) or moving along a fixed direction
            (Eq. 45–48) does not keep the volume, and that a cascade of the two solutions
            does. This is such a cascade, through virtual spines whose curvature is ``w``
            times the real one: on the posed side the normal bend into ``wκ1`` (with the
            stretch ``λ^w``), ``x1 − ½wκ1x1² = x/λ^w``, then the binormal unbend at ``wκ1``
            and the binormal bend into ``κ1`` (with the stretch ``λ^(1−w)``),
            ``y1 = y (1 − wκ1x1) / (λ^(1−w) (1 − κ1x1))``; on the rest side the mirror image
            (``y* = y0 (1 − κ0x0)/(1 − wκ0x0)``, ``x* = x0 (1 − ½wκ0x0)``). Every stage carries
            the volume element ``σ (1 − κx)`` of one spine onto the next, so the map has
            Jacobian determinant 1 for every ``w``. Fold-over is clamped as for the two
            solutions (focal point ``1/(wκ1)``, binormal factors capped at ``1e-3``).
        ``"none"``
            the uncorrected map (same local offset in the posed frame), as industry curve
            deformers do; not volume preserving — for comparison.

        ``κ`` is the curvature toward the centre of curvature; ``λ = σ1/σ0`` the stretch
        (new/old speed of the spine at the vertex's parameter). The binormal coordinate and
        the radial angle are read in the posed frame after the transfer (as Zhuo's Eq. 21
        with ``θ1`` implies). In the
        model of the spine used here (cubic Hermite positions and tangents) the map has
        Jacobian determinant 1 inside every edge slab, whatever the sampling.

        With ``stretchable=False`` the posed spine is first resampled by a compass walk along
        its polyline from its first point: sample ``i + 1`` is the next point of the
        polyline at the rest spine's chord ``|R_{i+1} − R_i|`` from sample ``i`` (past its end:
        along its last edge), so every edge keeps its rest length and the shape neither slides
        nor stretches (a posed spine shorter than the rest spine is extended straight). With
        ``stretchable=True`` the posed spine must have the rest spine's sample count and
        sample ``i`` carries the sections of rest sample ``i``: lengthening a part of it
        thins that part (λ > 1), compressing thickens it. A closed spine (``closed=True`` at
        binding) cannot keep every edge length when the loop's length changes: without
        ``stretchable`` it is resampled at the rest samples' fractions of its length (chord
        length along the posed loop), so the stretch ``λ = L1/L0`` is spread evenly and a
        uniformly scaled ring keeps its volume.

        The posed frames are the RMF of the posed spine started from the rest spine's first
        reference vector turned by the minimal rotation of the first tangent and rolled by the
        twist (about that tangent) of the best-fit (Kabsch) rotation of rest onto posed
        samples (no roll when either spine is straight); so the identity pose returns the
        input, a rigid motion of the spine moves the shape rigidly, and swapping the two
        spines (the posed one as returned by :meth:`posed_spine`) inverts the map — exactly
        for ``"radial"`` and ``"none"``; ``"normal"``/``"binormal"`` stretch along the posed
        spine's N/B (the thesis leaves open whether the stretch comes before or after the
        change of frame; both keep the volume), so they invert exactly only where the stretch
        is 1.

        The roll of the posed spine about its tangent can instead be given
        (``posed_frames`` or ``posed_up``): this is what a rig drives, and what fixes a rigid
        motion of a straight spine, whose roll no best fit can recover. The posed frames keep
        the posed spine's tangents and take the given reference vectors ``r``, blended
        linearly to where the used samples lie on the caller's polyline and projected onto
        their normal planes (made unit). So ``posed_frames = R @ binding.rest_frames`` with
        the spine moved by ``x ↦ Rx + c`` moves the shape rigidly (to round-off) whatever
        the spine, and rolling those frames by ``θ`` about a straight spine turns the shape by
        ``θ`` about it. The offsets are carried over in these frames, so the volume is kept
        as before (the transfer is a rotation about the tangent).

        Parameters
        ----------
        posed_spine : array_like (m, 3) or (m, 2)
        solution : "radial", "normal", "binormal", "blend" or "none"
            In 2D every corrected solution is the planar quadratic (Eq. 2/7).
        blend : float, optional
            With ``solution="blend"`` (and only then; required there): the weight
            ``w ∈ [0, 1]`` of the normal solution.
        stretchable : bool
        twist : float or array_like (n,), optional
            Extra rotation (rad, right-handed about the posed tangent) of the cross-section
            in the transfer step, one per rest sample or one for all; volume preserving.
        strict : bool
            Raise ``ValueError`` instead of warning when vertices are clamped.
        return_clamped : bool
            Also return the indices of the clamped vertices.
        posed_frames : array_like (m, 3, 3) or (3, 3), optional
            Frames of the posed spine at its ``m`` rows (columns ``r, s, t`` as
            :func:`spinal.frames` gives them; proper rotations, their ``t`` within 60° of the
            posed spine's tangent); only their ``r`` columns are used, as described above.
            One ``(3, 3)`` frame sets the first frame only: the posed frames are then the RMF
            started from its ``r``. 3D only (in the plane the frame is fixed).
        posed_up : array_like (3,) or (m, 3), optional
            Instead of ``posed_frames``: "up" vectors, one for all rows (a level horizon) or
            one per row; ``r`` is their projection onto each normal plane (refused where one
            is within 1e-3 of the tangent's direction).
        slide : float
            Move the shape along the posed spine by this arc length (units of the input; a
            snake crawling along its path): the compass walk starts at the point at arc
            length ``slide`` along the posed polyline (past its ends on the straight
            extension of the end edge; round a loop, modulo its length), so each section
            is unbent at its rest place and bent at the new one and the volume is kept as
            for a bend. On a straight spine the shape translates by ``slide`` along it; on a
            circular arc it turns about the arc's centre by ``slide/ρ``. Not with
            ``stretchable=True``.

        Returns
        -------
        ndarray (V, 3) or (V, 2) float64, and with ``return_clamped`` the int64 indices of
        the vertices whose offset had no fold-free solution (bend past the existence limit:
        clamped to the largest safe offset — the focal point ``1/κ1`` for normal and radial,
        ``1 − κ1x ≥ 1e-3`` for binormal — or lying past the rest spine's centre of
        curvature). Those vertices do not keep their volume; the output never holds NaN.
        They are also stored in ``self.clamped`` and reported by a
        :class:`spinal.FoldOverWarning` (``indices`` attribute).
        """
        out: Float64Array | tuple[Float64Array, Int64Array] = self._deform(posed_spine, solution, stretchable, twist, strict, return_clamped,
                            posed_frames, posed_up, slide, blend)
        return out

    def _deform(self, posed_spine: Array, solution: SpineSolution, stretchable: bool,
                twist: float | Array | None, strict: bool, return_clamped: bool,
                posed_frames: Array | None, posed_up: Array | None, slide: float,
                blend: float | None = None) -> Float64Array | tuple[Float64Array, Int64Array]:
        """:meth:`deform` (also of :func:`flesh`: either is two frames above this one, so
        a clamp warning points at the caller's line)."""
        solution = as_choice(solution, "solution", SOLUTIONS)
        blend = _blend(blend)
        strict = as_bool(strict, "strict")
        return_clamped = as_bool(return_clamped, "return_clamped")
        given = posed_frames is not None or posed_up is not None
        if posed_frames is not None and posed_up is not None:
            raise TypeError("posed_frames, posed_up: pass one of them, not both")
        if given and self._dim == 2:
            raise TypeError(f"{'posed_frames' if posed_frames is not None else 'posed_up'}: "
                            f"not used in the plane (the frame is fixed by the plane)")
        posed, m, at = self._posed(posed_spine, stretchable, _motion.as_slide(slide))
        frames1 = None
        if given:
            frames1 = _spine_frames(posed, "posed_spine", closed=self._closed)
            frames1 = _given_roll(frames1, posed_frames, posed_up, at, m, self._closed)
        out, _ = self._apply(posed, frames1, solution, twist, strict, level=5, blend=blend)
        return (out, self.clamped) if return_clamped else out

    def _apply(self, posed: np.ndarray, frames1: np.ndarray | None, solution: str,
               twist: float | Array | None, strict: bool, level: int,
               blend: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The shape on the used posed spine ``posed`` with the frames ``frames1`` (None: the
        default posed frames): the deformed vertices and the frames used. A clamp warning
        points ``level`` frames up from the warning."""
        if frames1 is None:
            frames1 = self._posed_frames(posed)
        tw = None if twist is None else _twist(twist, len(self._rest))
        c = self._closed
        if tw is not None:
            tw = _loop(tw, c)
        # in the plane every corrected solution is the planar quadratic (the core checks
        # `blend` first)
        out, flags = _core.flesh_deform(_loop(posed, c), _loop(frames1, c), self._edge,
                                        self._coords, {"solution": solution, "twist": tw,
                                                       "closed": c, "blend": blend,
                                                       "planar": self._dim == 2})
        self.clamped = _report_clamped(flags, strict, level)
        if self._dim == 2:
            out = np.ascontiguousarray(out[:, :2])
        return out, frames1

    def animate(
        self,
        posed_spines_t: Array,
        *,
        solution: SpineSolution = "radial",
        blend: float | None = None,
        stretchable: bool = False,
        twist: float | Array | None = None,
        slide: float | Array = 0.0,
        previous_weight: float = 1000.0,
        progress: ProgressArg = False,
    ) -> Float64Array:
        r"""The shape posed on a sequence of posed spines, with frames that follow each
        other in time: ``(T, V, 3)`` (or ``(T, V, 2)`` in the plane).

        Pose 0 is :meth:`deform` of ``posed_spines_t[0]``; every later pose's frames are
        :func:`spinal.frames` of its posed spine (as :meth:`deform` uses it) with
        ``previous=`` the frames of the pose before and ``previous_twist=True``, weighted by
        ``previous_weight`` (see :func:`spinal.frames_in_time`): each section turns between
        poses by about as much as the spine's tangent there does, however the spine's own
        twist changes, so the shape does not flicker where a per-pose best fit of the roll
        would jump (a spine passing through a straight pose). The volume is kept per pose
        as by :meth:`deform`.

        Parameters
        ----------
        posed_spines_t : array_like (T, m, 3) or (T, m, 2)
            One posed spine per pose (the same row count ``m`` at every pose).
        solution, blend, stretchable, twist
            As in :meth:`deform`, for every pose.
        slide : float or array_like (T,)
            Arc length to slide the shape along each pose's spine (see :meth:`deform`): one
            for all poses or one per pose (a crawl: ``np.linspace(0, d, T)``).
        previous_weight : float
            The weight of the pose before's ``r`` against the twist rate (> 0).
        progress : bool or callable
            Report the poses done: ``True`` shows a bar (tqdm when installed, in a terminal
            or a notebook) or a line on stderr at every tenth; a callable is called as
            ``progress(done, T)``.

        Ctrl-C stops it between poses; each pose is computed in parallel over the vertices.
        Vertices clamped in some pose (past the fold limit) are reported by one
        :class:`spinal.FoldOverWarning` for the call, whose ``indices`` are every vertex
        clamped in any pose (the message counts the poses and names the worst);
        ``self.clamped`` holds those of the last pose.
        """
        solution = as_choice(solution, "solution", SOLUTIONS)
        blend = _blend(blend)
        return _motion.animate(self, posed_spines_t, solution, stretchable, twist, slide,
                               previous_weight, progress, blend)

    def _posed_frames(self, posed: np.ndarray) -> np.ndarray:
        """The frames of the posed spine: its RMF started from the reference vector of
        :func:`_posed_initial` (in the plane: ``r`` the left normal ``z × t``)."""
        if self._dim == 2:  # r is the left normal z × t all along a planar RMF
            t1 = posed[1] - posed[0]
            return _spine_frames(posed, "posed_spine", initial=[-t1[1], t1[0], 0.0],
                                 closed=self._closed)
        # the RMF is linear in its initial vector: start from the default one and roll
        # every frame by the constant angle that brings it to the chosen start
        frames1 = _spine_frames(posed, "posed_spine", closed=self._closed)
        init = _posed_initial(self._rest, self._frames[0], posed, frames1[0][:, 2])
        return _roll_to(frames1, init, "posed_spine")


def _blend(blend: object) -> float | None:
    """``blend`` as a Python float (or ``None``); the core checks its value and that it
    comes with ``solution="blend"``."""
    return None if blend is None else as_real(blend, "blend")


def _twist(twist: float | Array, n: int) -> np.ndarray:
    """``twist`` as ``(n,)`` angles (a number is used for every sample); the core checks
    the values."""
    tw = as_float_array(twist, "twist")
    if tw.ndim == 0:
        tw = np.full(n, float(tw))
    if tw.shape != (n,):
        raise ValueError(f"twist: expected a number or shape ({n},), got {tw.shape}")
    return np.ascontiguousarray(tw)


def _report_clamped(flags: np.ndarray, strict: bool, level: int = 3) -> np.ndarray:
    """Indices of the clamped vertices; warned about (raised with ``strict``), the warning
    pointing ``level`` frames up."""
    clamped = np.flatnonzero(flags).astype(np.int64)
    if clamped.size:
        msg = (
            f"posed_spine: {clamped.size} vertices have no fold-free offset (bent past the "
            f"existence limit) and were clamped, e.g. vertex {clamped[0]}"
        )
        if strict:
            raise ValueError(msg)
        warnings.warn(FoldOverWarning(msg, clamped), stacklevel=level)
    return clamped


@overload
def flesh(
    vertices: Array,
    rest_spine: Array,
    posed_spine: Array,
    *,
    solution: SpineSolution = "radial",
    blend: float | None = None,
    stretchable: bool = False,
    twist: float | Array | None = None,
    strict: bool = False,
    return_clamped: Literal[False] = False,
    closed: bool = False,
    posed_frames: Array | None = None,
    posed_up: Array | None = None,
) -> Float64Array: ...


@overload
def flesh(
    vertices: Array,
    rest_spine: Array,
    posed_spine: Array,
    *,
    solution: SpineSolution = "radial",
    blend: float | None = None,
    stretchable: bool = False,
    twist: float | Array | None = None,
    strict: bool = False,
    return_clamped: Literal[True],
    closed: bool = False,
    posed_frames: Array | None = None,
    posed_up: Array | None = None,
) -> tuple[Float64Array, Int64Array]: ...


@overload
def flesh(
    vertices: Array,
    rest_spine: Array,
    posed_spine: Array,
    *,
    solution: SpineSolution = "radial",
    blend: float | None = None,
    stretchable: bool = False,
    twist: float | Array | None = None,
    strict: bool = False,
    return_clamped: bool = False,
    closed: bool = False,
    posed_frames: Array | None = None,
    posed_up: Array | None = None,
) -> Float64Array | tuple[Float64Array, Int64Array]: ...


def flesh(
    vertices: Array,
    rest_spine: Array,
    posed_spine: Array,
    *,
    solution: SpineSolution = "radial",
    blend: float | None = None,
    stretchable: bool = False,
    twist: float | Array | None = None,
    strict: bool = False,
    return_clamped: bool = False,
    closed: bool = False,
    posed_frames: Array | None = None,
    posed_up: Array | None = None,
) -> Float64Array | tuple[Float64Array, Int64Array]:
    r"""Bend a shape with its spine and keep its volume locally (Zhuo 2014): ``(V, 3)``.

    One-shot form of ``SpineBinding(vertices, rest_spine).deform(posed_spine, ...)``; see
    :class:`SpineBinding` for the registration and :meth:`SpineBinding.deform` for the
    solutions (``"radial"``, ``"normal"``, ``"binormal"``, ``"blend"`` between the last two
    with the weight ``blend``, and ``"none"`` the uncorrected map), ``stretchable`` (without it the posed spine is resampled to the rest spine's
    length), ``twist``, ``posed_frames``/``posed_up`` (the roll of the posed spine, e.g.
    driven by a rig), fold-over clamping and errors; ``closed`` for loops (rings).
    2-column input is the planar case.

    >>> import numpy as np, spinal
    >>> rest = np.c_[np.linspace(-1, 1, 201), np.zeros(201), np.zeros(201)]
    >>> u = np.linspace(-1, 1, 201)          # the same length bent into a unit-radius arc
    >>> posed = np.c_[np.sin(u), 1 - np.cos(u), np.zeros(201)]
    >>> P = spinal.flesh([[0, 0.3, 0]], rest, posed)   # 0.3 toward the centre of curvature
    >>> round(1 - np.linalg.norm(P[0] - [0, 1, 0]), 6)  # radial: r1²(1 − ⅔ r1) = 0.09
    0.341342
    """
    try:
        binding = SpineBinding(vertices, rest_spine, closed=closed)
    except MemoryError as e:
        raise MemoryError(f"flesh: {e}") from None
    out: Float64Array | tuple[Float64Array, Int64Array] = binding._deform(posed_spine, solution, stretchable, twist, strict, return_clamped,
                           posed_frames, posed_up, 0.0, blend)
    return out
