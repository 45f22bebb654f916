"""Sweeps and tubes: the Python face of ``spinal._core.sweep_mesh``."""

from __future__ import annotations

import warnings

import numpy as np

from . import _core
from ._frames import DEFAULT_TANGENT_RULE, TANGENT_RULES, estimate_tangents
from ._frames import frames as _frames
from ._mesh import FoldOverWarning, Mesh
from ._validate import (
    as_bool,
    as_choice,
    as_float_array,
    as_frames,
    as_int,
    as_offsets,
    as_per_row,
    as_points,
)

__all__ = ["sweep", "tube"]

#: Most sides of a :func:`tube` (a 2**20-gon is round to 5e-12 of its radius).
MAX_SIDES = 2**20


def _dtype(dtype) -> bool:
    """True for float32 output, False for float64; anything else is refused by name."""
    try:
        dt = np.dtype(dtype)
    except TypeError:
        dt = None
    if dt is None or dt not in (np.dtype(np.float64), np.dtype(np.float32)):
        raise ValueError(f"dtype: expected numpy.float64 or numpy.float32, got {dtype!r}")
    return dt == np.float32


def _scale_rows(scale, name: str, n: int) -> np.ndarray:
    """The scale as ``(n, 2)`` rows, or one ``(1, 2)`` row when it is the same everywhere
    (the core broadcasts it; no per-row copy)."""
    if scale is None:
        return np.ones((1, 2))
    a = as_float_array(scale, name)
    if a.ndim == 0:
        return np.full((1, 2), float(a))
    return as_per_row(a, name, n, pair=True)


def _ranges(rows: np.ndarray) -> str:
    """'3–7, 12, 20–21' for sorted integer rows."""
    parts, start, prev = [], None, None
    for r in list(rows) + [None]:
        if r is not None and prev is not None and r == prev + 1:
            prev = r
            continue
        if start is not None:
            parts.append(str(start) if start == prev else f"{start}–{prev}")
        start = prev = r
    return ", ".join(parts)


def sweep(
    points,
    profile,
    *,
    frames=None,
    scale=None,
    twist=None,
    closed: bool = False,
    caps: bool = True,
    profile_closed: bool = True,
    miter_limit: float = 4.0,
    split_seams: bool = False,
    strict: bool = False,
    lengths=None,
    offsets=None,
    tangents=None,
    tangent_rule: str = DEFAULT_TANGENT_RULE,
    dtype="float64",
    normals: bool = True,
    uv: bool = True,
) -> Mesh:
    """Sweep a profile polygon along a spine into a triangle mesh.

    Ring ``i`` of the mesh is the profile placed in the normal plane of spine sample
    ``x_i`` with the frame ``(r_i, s_i, t_i)``::

        v_ij = x_i + M_i (a'_j r_i + b'_j s_i),    (a', b') = Rot(twist_i) (scale_i ⊙ (a_j, b_j))

    where ``M_i`` is the mitre stretch: at a sample where the spine turns by the angle φ
    between its chords, the ring is stretched by ``1/cos(φ/2)`` (at most ``miter_limit``)
    along the direction of the turn, so tubes keep their cross-section through corners
    instead of pinching. On smooth, densely sampled spines this is ``1 + κ²h²/8``.

    Parameters
    ----------
    points : array_like (n, 3)
        Spine samples (several spines back to back with ``lengths``/``offsets``).
    profile : array_like (m, 2)
        Polygon in the normal plane, coordinates along ``(r, s)``. Closed by default (a
        repeated first vertex at the end is accepted; either orientation: faces are wound
        outwards); it must be simple (not self-intersecting). ``profile_closed=False``
        sweeps an open polyline (a ribbon, an open moulding): no caps.
    frames : array_like (n, 3, 3), optional
        Frames from :func:`spinal.frames` (columns r, s, t). Default: the rotation-minimising
        frames by double reflection, ``spinal.frames(points, closed=closed)``, so closed
        loops meet without a seam twist.
    scale : float, (n,) or (n, 2), optional
        Positive scale of the profile at every sample (per profile axis for (n, 2)).
    twist : float or (n,), optional
        Extra rotation of the profile about the tangent, radians (counter-clockwise from r
        towards s).
    closed : bool
        The spine is a loop (a repeated first point at the end is accepted): the last ring
        is joined to the first; no caps.
    caps : bool
        Close the ends of an open spine with the triangulated profile (ear clipping, so
        non-convex profiles work); the mesh is then watertight.
    miter_limit : float
        Largest mitre stretch (≥ 1; 1 switches the stretch off).
    split_seams : bool
        Duplicate the vertices on the texture seams — the profile's first vertex (v = 0 and
        v = 1) and, on a closed spine, the first ring (u = 0 and u = L) — so every face has
        continuous ``uv`` for texturing. The mesh is then watertight only after merging
        coincident vertices; keep the default for volumes and booleans.
    strict : bool
        Raise a ValueError instead of a :class:`FoldOverWarning` where the profile reaches
        past the spine's centre of curvature.
    lengths, offsets : array_like of int, optional
        Many spines back to back, as in :func:`spinal.frames`.
    tangents : array_like (n, 3), optional
        The spine's tangent directions (normalised here), instead of estimating them: the
        default frames become ``spinal.frames(points, tangents, closed=closed)`` (double
        reflection with these tangents, Wang et al. 2008 §4), whose ``t`` column they are.
    tangent_rule : str
        How the tangents are estimated when neither ``frames`` nor ``tangents`` is given:
        a ``method`` of :func:`spinal.estimate_tangents` — ``"five_point_bounded"`` (default:
        the 4th-order five-point chord-length rule whose end tangents lean from the end chord
        by at most the turn of the last two chords, so coarse spines get no chisel-shaped
        ends), ``"five_point"`` (ends unbounded), ``"five_point_uniform"`` or ``"circle"``.
    dtype : "float64" or "float32" (or numpy.float64, numpy.float32)
        Precision of ``vertices``, ``normals`` and ``uv``. With ``float32`` everything is
        still computed in double precision and stored rounded (the same topology, vertices
        within float32 rounding of the float64 ones), and the faces are int32 when the
        vertex count fits: 56 bytes per vertex instead of 112.
    normals, uv : bool
        Compute the normals / texture coordinates (``False``: ``None`` in the mesh, less
        memory and time).

    Returns
    -------
    Mesh
        ``vertices`` (V, 3), ``faces`` (F, 3), ``normals`` (V, 3) — normals of the smooth
        swept surface, tilted by a varying radius —, ``uv`` (V, 2) (u = spine arc length,
        v = profile arc length / perimeter) and ``fold_over`` (spine rows). Vertex
        ``k * m + j`` (per spine) is profile vertex ``j`` on ring ``k``. The quads between
        rings are split along alternating diagonals (a checkerboard), so the volume of
        twisted sweeps converges at second order.

    Raises
    ------
    ValueError, TypeError
        Bad shapes, non-finite values, repeated consecutive points, a self-intersecting or
        zero-area profile, non-positive scale, frames that are not rotations or whose
        tangent runs against the spine (frames of the reversed curve), tangents of the
        wrong shape or of zero length, ``tangents``/``tangent_rule`` together with ``frames``
        (or with each other), and everything :func:`spinal.frames` refuses.
    """
    return _sweep_mesh(points, profile, frames, scale, twist, closed, caps, profile_closed,
                       miter_limit, split_seams, strict, lengths, offsets, "scale",
                       tangents, tangent_rule, dtype, normals, uv)


def _sweep_frames(pts, frames, closed, offs, bundle, tangents, tangent_rule):
    """The sweep's frames: given, or the RMF with the given or estimated tangents."""
    rule = as_choice(tangent_rule, "tangent_rule", TANGENT_RULES)
    n = pts.shape[0]
    if frames is not None:
        if tangents is not None or rule != DEFAULT_TANGENT_RULE:
            which = "tangents" if tangents is not None else "tangent_rule"
            raise TypeError(f"{which}: not used with frames= (the frames' t column is the "
                            f"tangent)")
        fr, _ = as_frames(frames, "frames", rows=n)
        return fr
    kw = {"offsets": offs} if bundle else {}
    if tangents is not None:
        if rule != DEFAULT_TANGENT_RULE:
            raise TypeError("tangent_rule: not used with tangents= (they replace the estimate)")
        tg = as_points(tangents, "tangents")
        if tg.shape[0] != n:
            raise ValueError(f"tangents: expected shape ({n}, 3) to match points, got "
                             f"{tg.shape}")
        return _frames(pts, tg, closed=closed, **kw)
    if rule != DEFAULT_TANGENT_RULE:
        tg = estimate_tangents(pts, closed=closed, method=rule, **kw)
        return _frames(pts, tg, closed=closed, **kw)
    return _frames(pts, closed=closed, **kw)


def _sweep_mesh(points, profile, frames, scale, twist, closed, caps, profile_closed,
                miter_limit, split_seams, strict, lengths, offsets, scale_arg,
                tangents=None, tangent_rule=DEFAULT_TANGENT_RULE, dtype="float64",
                normals=True, uv=True) -> Mesh:
    """:func:`sweep`, with the scale's errors naming ``scale_arg`` (called one level below
    the public function, which the warnings point at)."""
    pts = as_points(points, "points")
    n = pts.shape[0]
    closed = as_bool(closed, "closed")
    caps = as_bool(caps, "caps")
    profile_closed = as_bool(profile_closed, "profile_closed")
    split_seams = as_bool(split_seams, "split_seams")
    strict = as_bool(strict, "strict")
    single = _dtype(dtype)
    want_normals = as_bool(normals, "normals")
    want_uv = as_bool(uv, "uv")
    miter_limit = float(as_float_array(miter_limit, "miter_limit"))
    prof = as_float_array(profile, "profile")
    if prof.ndim != 2 or prof.shape[1] != 2:
        raise ValueError(f"profile: expected an array of shape (m, 2), got shape {prof.shape}")
    offs, bundle = as_offsets(n, lengths, offsets)
    fr = _sweep_frames(pts, frames, closed, offs, bundle, tangents, tangent_rule)
    sc = _scale_rows(scale, scale_arg, n)
    tw = None if twist is None else as_per_row(twist, "twist", n)
    v, f, nrm, uv, folds = _core.sweep_mesh(
        pts, fr, sc, tw, offs, np.ascontiguousarray(prof),
        profile_closed, closed, caps, miter_limit, split_seams, scale_arg,
        single, single, want_normals, want_uv,
    )
    if folds.size:
        msg = (
            f"the profile reaches past the spine's centre of curvature (the surface folds "
            f"over itself) on the segments starting at spine rows {_ranges(folds)}; sample "
            f"the spine more densely there, reduce the profile, or smooth the spine"
        )
        if strict:
            raise ValueError(f"points: {msg}")
        warnings.warn(FoldOverWarning(msg, folds), stacklevel=3)
    return Mesh(v, f, nrm, uv, folds)


def tube(
    points,
    radius=1.0,
    sides: int = 16,
    *,
    frames=None,
    closed: bool = False,
    caps: bool = True,
    miter_limit: float = 4.0,
    split_seams: bool = False,
    strict: bool = False,
    lengths=None,
    offsets=None,
    tangents=None,
    tangent_rule: str = DEFAULT_TANGENT_RULE,
    dtype="float64",
    normals: bool = True,
    uv: bool = True,
) -> Mesh:
    """A tube of the given radius around a spine: :func:`sweep` of a regular polygon with
    ``sides`` vertices on the unit circle (vertex ``j`` at angle ``2πj/sides`` from r
    towards s), scaled by ``radius``.

    The cross-section is the inscribed polygon, of area ``(sides/2) ρ² sin(2π/sides)``.
    ``radius``: scalar or (n,) positive values (one per spine row); the normals are tilted
    by the radius slope. ``sides``: 3 to 2**20. Other arguments (``tangents``,
    ``tangent_rule``, ``dtype=numpy.float32``, ``normals``, ``uv``) as in :func:`sweep`.
    """
    sides = as_int(sides, "sides")
    if sides < 3:  # the core sees only the polygon built here
        raise ValueError(f"sides: a tube needs at least 3 sides, got {sides}")
    if sides > MAX_SIDES:
        raise ValueError(f"sides: at most {MAX_SIDES:,} (2**20) sides, got {sides:,}")
    a = 2 * np.pi * np.arange(sides) / sides
    profile = np.stack([np.cos(a), np.sin(a)], axis=1)
    pts = as_points(points, "points")
    rad = as_float_array(radius, "radius")  # the core checks the values, naming radius
    if rad.ndim:
        rad = as_per_row(rad, "radius", pts.shape[0])
    return _sweep_mesh(pts, profile, frames, rad, None, closed, caps, True, miter_limit,
                       split_seams, strict, lengths, offsets, "radius", tangents, tangent_rule,
                       dtype, normals, uv)
