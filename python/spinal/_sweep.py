"""Sweeps and tubes: the Python face of ``spinal._core.sweep_mesh``."""

from __future__ import annotations

import warnings

import numpy as np

from . import _core
from ._frames import frames as _frames
from ._mesh import FoldOverWarning, Mesh
from ._validate import (
    as_bool,
    as_float_array,
    as_frames,
    as_int,
    as_offsets,
    as_per_row,
    as_points,
    as_real,
)

__all__ = ["sweep", "tube"]


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

    Returns
    -------
    Mesh
        ``vertices`` (V, 3), ``faces`` (F, 3), ``normals`` (V, 3) — normals of the smooth
        swept surface, tilted by a varying radius —, ``uv`` (V, 2) (u = spine arc length,
        v = profile arc length / perimeter) and ``fold_over`` (spine rows). Vertex
        ``k * m + j`` (per spine) is profile vertex ``j`` on ring ``k``.

    Raises
    ------
    ValueError, TypeError
        Bad shapes, non-finite values, repeated consecutive points, a self-intersecting or
        zero-area profile, non-positive scale, frames that are not rotations, and
        everything :func:`spinal.frames` refuses.
    """
    return _sweep_mesh(points, profile, frames, scale, twist, closed, caps, profile_closed,
                       miter_limit, split_seams, strict, lengths, offsets, "scale")


def _sweep_mesh(points, profile, frames, scale, twist, closed, caps, profile_closed,
                miter_limit, split_seams, strict, lengths, offsets, scale_arg) -> Mesh:
    """:func:`sweep`, with the scale's errors naming ``scale_arg`` (called one level below
    the public function, which the warnings point at)."""
    pts = as_points(points, "points")
    n = pts.shape[0]
    closed = as_bool(closed, "closed")
    caps = as_bool(caps, "caps")
    profile_closed = as_bool(profile_closed, "profile_closed")
    split_seams = as_bool(split_seams, "split_seams")
    strict = as_bool(strict, "strict")
    miter_limit = as_real(miter_limit, "miter_limit")  # the core checks the range
    prof = as_float_array(profile, "profile")
    if prof.ndim != 2 or prof.shape[1] != 2:
        raise ValueError(f"profile: expected an array of shape (m, 2), got shape {prof.shape}")
    offs, bundle = as_offsets(n, lengths, offsets)
    if frames is None:
        kw = {"offsets": offs} if bundle else {}
        fr = _frames(pts, closed=closed, **kw)
    else:
        fr, _ = as_frames(frames, "frames", rows=n)
    sc = np.ones((n, 2)) if scale is None else as_per_row(scale, "scale", n, pair=True)
    tw = None if twist is None else as_per_row(twist, "twist", n)
    v, f, nrm, uv, folds = _core.sweep_mesh(
        pts, fr, sc, tw, offs, np.ascontiguousarray(prof),
        profile_closed, closed, caps, miter_limit, split_seams, scale_arg,
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
) -> Mesh:
    """A tube of the given radius around a spine: :func:`sweep` of a regular polygon with
    ``sides`` vertices on the unit circle (vertex ``j`` at angle ``2πj/sides`` from r
    towards s), scaled by ``radius``.

    The cross-section is the inscribed polygon, of area ``(sides/2) ρ² sin(2π/sides)``.
    ``radius``: scalar or (n,) positive values (one per spine row); the normals are tilted
    by the radius slope. Other arguments as in :func:`sweep`.
    """
    sides = as_int(sides, "sides")
    if sides < 3:  # the core sees only the polygon built here
        raise ValueError(f"sides: a tube needs at least 3 sides, got {sides}")
    a = 2 * np.pi * np.arange(sides) / sides
    profile = np.stack([np.cos(a), np.sin(a)], axis=1)
    pts = as_points(points, "points")
    rad = as_per_row(radius, "radius", pts.shape[0])  # the core checks it, naming radius
    return _sweep_mesh(pts, profile, frames, rad, None, closed, caps, True, miter_limit,
                       split_seams, strict, lengths, offsets, "radius")
