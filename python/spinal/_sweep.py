"""Sweeps and tubes: the Python face of ``spinal._core.sweep_mesh``."""

from __future__ import annotations

import functools
import re
import warnings
from collections.abc import Callable
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from . import _core, _merge
from ._frames import estimate_tangents
from ._frames_args import DEFAULT_TANGENT_RULE, TANGENT_RULES
from ._mesh import FoldOverWarning, Mesh, PrecisionWarning, SkippedCurvesWarning
from ._progress import Reported, checked
from ._types import Array, CurveBundle, Ints, PointData, ProgressArg, TangentRule
from ._validate import (
    as_bool,
    as_choice,
    as_curves,
    as_float_array,
    as_frames,
    as_int,
    as_out,
    as_per_row,
    as_points,
    as_real,
    as_turns,
    fill_out,
)

__all__ = ["sweep", "tube"]

#: Most sides of a :func:`tube` (a 2**20-gon is round to 5e-12 of its radius).
MAX_SIDES = 2**20



def _dtype(dtype: npt.DTypeLike) -> bool:
    """True for float32 output, False for float64; anything else is refused by name."""
    dt: np.dtype[Any] | None
    try:
        dt = np.dtype(dtype)
    except TypeError:
        dt = None
    if dt is None or dt not in (np.dtype(np.float64), np.dtype(np.float32)):
        raise ValueError(f"dtype: expected numpy.float64 or numpy.float32, got {dtype!r}")
    out: bool = dt == np.float32
    return out


def _scale_rows(scale: object, name: str, n: int, lens: np.ndarray | None) -> np.ndarray:
    """The scale as ``(n, 2)`` rows, or one ``(1, 2)`` row when it is the same everywhere
    (the core broadcasts it; no per-row copy). ``lens``: the curves' row counts of a bundle,
    for a value per curve; a tube's ``radius`` is one value per row (or curve)."""
    if scale is None:
        return np.ones((1, 2))
    a = as_float_array(scale, name)
    if a.ndim == 0:
        return np.full((1, 2), float(a))
    pair = name == "scale"
    a = _per_row_or_curve(a, name, n, lens, pair=pair)
    return np.ascontiguousarray(a if pair else np.stack([a, a], axis=1))


def _ranges(rows: np.ndarray, most: int = 20) -> str:
    """'3–7, 12, 20–21' for sorted integer rows; past ``most`` ranges, '… and k more
    (n rows in all)', so a message stays readable on a curve of millions of rows."""
    rows = np.asarray(rows, dtype=np.int64)
    if rows.size == 0:
        return ""
    # the starts of runs of consecutive rows
    cut = np.flatnonzero(np.diff(rows) != 1) + 1
    starts, ends = np.r_[0, cut], np.r_[cut, rows.size] - 1
    parts = [str(rows[a]) if a == b else f"{rows[a]}–{rows[b]}"
             for a, b in zip(starts[:most], ends[:most], strict=True)]
    if len(starts) > most:
        parts.append(f"… and {len(starts) - most:,} more ({rows.size:,} rows in all)")
    return ", ".join(parts)


def sweep(
    points: Array | CurveBundle,
    profile: Array,
    *,
    frames: Array | None = None,
    scale: float | Array | None = None,
    twist: float | Array | None = None,
    closed: bool = False,
    caps: bool = True,
    profile_closed: bool = True,
    miter_limit: float = 4.0,
    split_seams: bool = False,
    strict: bool = False,
    lengths: Ints | None = None,
    offsets: Ints | None = None,
    tangents: Array | None = None,
    tangent_rule: TangentRule = "five_point_bounded",
    dtype: npt.DTypeLike = "float64",
    normals: bool = True,
    uv: bool = True,
    point_data: PointData | None = None,
    on_short: Literal["raise", "skip"] = "raise",
    on_invalid: Literal["raise", "skip"] = "raise",
    join: Literal["round", "bevel", "miter"] = "round",
    progress: ProgressArg = False,
    turns: float = 0,
    out: Mesh | None = None,
) -> Mesh:
    """Sweep a profile polygon along a spine into a triangle mesh.

    Ring ``i`` of the mesh is the profile placed in the normal plane of spine sample
    ``x_i`` with the frame ``(r_i, s_i, t_i)``::

        v_ij = x_i + M_i (a'_j r_i + b'_j s_i),    (a', b') = Rot(twist_i) (scale_i ⊙ (a_j, b_j))

    where ``M_i`` is the mitre stretch: at a sample where the spine turns by the angle φ
    between its chords, the ring is stretched by ``1/cos(φ/2)`` (at most ``miter_limit``)
    along the direction of the turn, so tubes keep their cross-section through corners
    instead of pinching. On smooth, densely sampled spines this is ``1 + κ²h²/8``.

    Sharp corners are built as joins, as a 2D stroker joins two segments: where the chords
    at a sample turn by 60° or more, by 28° or more between straighter runs, or by 15° or
    more where the mitred ring would exceed ``miter_limit`` or cross a neighbouring
    sample's ring (a densely sampled corner), the two straight sweeps meeting there are
    joined exactly — the inner side cut where they meet
    (in the bisector plane of the corner; the neighbouring rings' vertices past it are
    merged into that crease), the outer side a round join (rings turning about the corner,
    at most ``2π/m`` apart for a profile of ``m`` vertices), a bevel or a mitre (``join``).
    The extra rings are stored after each curve's rings; ``sample_of`` maps them to the
    corner's row. Where straight runs on both sides of a corner are longer than
    ``ρ·tan(φ/2)`` (ρ the profile's reach), no faces cross; shorter ones (a hairpin
    tighter than the profile) are reported with a :class:`FoldOverWarning`.

    Parameters
    ----------
    points : array_like (n, 3), or a sequence of (n_i, 3) arrays
        Spine samples: one spine, several spines back to back with ``lengths``/``offsets``,
        or a bundle as users hold it: a list (any sequence) of ``(n_i, 3)`` arrays of any
        real dtype, e.g. nibabel's ``ArraySequence`` of streamlines (then curve ``c`` is
        ``points[c]`` and the rows of all curves are numbered back to back).
    profile : array_like (m, 2)
        Polygon in the normal plane, coordinates along ``(r, s)``. Closed by default (a
        repeated first vertex at the end is accepted; either orientation: faces are wound
        outwards); it must be simple (not self-intersecting). ``profile_closed=False``
        sweeps an open polyline (a ribbon, an open moulding): no caps.
    frames : array_like (n, 3, 3), optional
        Frames from :func:`spinal.frames` (columns r, s, t). Default: the rotation-minimising
        frames by double reflection, ``spinal.frames(points, closed=closed)``, so closed
        loops meet without a seam twist (computed curve by curve as the sweep goes, bit for
        bit those of that call, without holding the ``(n, 3, 3)`` array of them).
    scale : float, (n,) or (n, 2), optional
        Positive scale of the profile at every sample (per profile axis for (n, 2)).
    twist : float or (n,), optional
        Extra rotation of the profile about the tangent, radians (counter-clockwise from r
        towards s).
    closed : bool
        The spine is a loop (a repeated first point at the end is accepted): the last ring
        is joined to the first (column to column, or with the half-turn shift of
        ``turns``); no caps.
    caps : bool
        Close the ends of an open spine with the triangulated profile (on its own
        vertices, so non-convex profiles work; O(m log m) in the profile's vertices); the
        mesh is then watertight.
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
        Several spines in ``points``, back to back: ``lengths[c]`` rows each, or curve ``c``
        in rows ``offsets[c]:offsets[c+1]``. ``scale`` (and ``radius`` of :func:`tube`)
        may then also be given per curve, ``(C,)`` (or ``(C, 2)``).
    tangents : array_like (n, 3), optional
        The spine's tangent directions (normalised here), instead of estimating them: the
        default frames become ``spinal.frames(points, tangents, closed=closed)`` (double
        reflection with these tangents, Wang et al. 2008 §4), whose ``t`` column they are.
    tangent_rule : str
        How the tangents are estimated when neither ``frames`` nor ``tangents`` is given:
        a ``method`` of :func:`spinal.estimate_tangents` — ``"five_point_bounded"`` (default:
        the 4th-order five-point chord-length rule whose end tangents lean from the end chord
        by at most half the turn of the last two chords (the whole turn where it is under
        10°, which keeps the 4th order) and at most 45°, so coarse spines get no
        chisel-shaped ends), ``"five_point"`` (ends unbounded), ``"five_point_uniform"`` or ``"circle"``.
    dtype : "float64" or "float32" (or numpy.float64, numpy.float32)
        Precision of ``vertices``, ``normals`` and ``uv``. With ``float32`` everything is
        still computed in double precision and stored rounded (the same topology, vertices
        within float32 rounding of the float64 ones), and the faces are int32 when the
        vertex count fits: 56 bytes per vertex instead of 112.
    normals, uv : bool
        Compute the normals / texture coordinates (``False``: ``None`` in the mesh, less
        memory and time).
    point_data : dict of str to array_like, optional
        Attributes carried onto the mesh: ``(n,)`` or ``(n, k)`` arrays, one value per spine
        row (of all curves), or for a bundle ``(C,)`` / ``(C, k)`` per curve, or a list of
        one ``(n_c,)`` / ``(n_c, k)`` array per curve (as dipy's ``values_from_volume``
        returns them). Every vertex of
        a ring (caps included) gets its sample's (curve's) value, in ``Mesh.point_data``
        with the dtype given.
    on_short : {"raise", "skip"}
        What to do with curves of a bundle that have too few rows to sweep (0 or 1; 2 on a
        closed spine): refuse them (ValueError) or leave them out, with a
        :class:`SkippedCurvesWarning` naming them and ``Mesh.skipped_curves``.
    on_invalid : {"raise", "skip"}
        What to do with curves (of a bundle, or the one curve) that hold a NaN or an
        infinity or have fewer than 2 (closed: 3) distinct points: refuse them (ValueError
        naming the curve and row) or leave them out like ``on_short="skip"`` (a
        :class:`SkippedCurvesWarning` naming them and why; ``Mesh.skipped_curves``). Curves
        of 0 or 1 rows have fewer than 2 distinct points: ``on_invalid="skip"`` leaves them
        out too, whatever ``on_short`` says.
    join : {"round", "bevel", "miter"}
        The outer side of the corners that get joins: rings turning about the corner
        (``"round"``: for a circular profile, the spherical wedge of the union of the two
        tubes), one flat band (``"bevel"``), or one ring in the bisector plane (``"miter"``,
        the exact mitre; a bevel where it would exceed ``miter_limit``). Smooth, well
        sampled spines get no joins, whichever is chosen.
    turns : int or float
        With ``closed=True``: extra turns of the default frames, those of
        ``spinal.frames(points, closed=True, turns=turns)`` (the closing twist ``α +
        2π·turns`` spread along the loop). A half number (``0.5``, ``-0.5``, ``1.5``, …)
        leaves the frames closing up to a half turn about the tangent, ``(r, s) → (−r, −s)``,
        which takes profile vertex ``p_j`` to ``−p_j``: the sweep still closes when the
        profile maps onto itself under that half turn, ``p_{j+m/2} = −p_j`` (a closed profile
        of an even number ``m`` of vertices, point symmetric about the spine to 1e-9 of its
        reach: an ellipse or rectangle centred on it, a tube of an even number of sides).
        The seam then joins column ``j`` of the last ring to column ``j + m/2 (mod m)`` of
        the first, every vertex shared: the mesh stays watertight and wound outwards (a
        torus; an open profile would close into a Möbius band and is refused), and the
        normals and the fold-over test see the ring across the seam turned by π, so they
        are those of the surface there as anywhere. ``u`` of ``uv`` jumps at the seam as it
        always does; with ``split_seams`` the copy of the first ring at ``u = L`` is that
        ring turned by π (its column ``j`` on the first ring's column ``j + m/2``), so
        every face's ``uv`` is continuous. A profile without the symmetry raises ValueError
        naming ``profile`` (a tube of an odd number of sides: ``turns``), as does a spine
        with corner joins (their rings are laid out column by column across the seam;
        sample the spine more densely). With ``frames=`` the frames carry their own twist:
        ``turns`` is 0 (they are joined column to column, as given) or a half number, which
        says that they close up to a half turn: the last frame, carried to the first
        tangent by the minimal rotation, must then be within π/2 of the first turned by π
        (else ValueError naming ``frames``); nonzero whole numbers raise TypeError.
    progress : bool or callable
        Report the spine rows swept (those of the spines done, in any order, after repeats
        are merged and skipped curves left out): ``True`` shows a bar (tqdm when installed,
        in a terminal or a notebook) or a line on stderr at every tenth; a callable is
        called as ``progress(rows_done, rows)`` from the calling thread, about every 20 ms
        while the count moves and once at the end. The work only counts (the same mesh, bit
        for bit, at the same speed).
    out : Mesh, optional
        A mesh of an earlier sweep (or tube) of the same sizes whose ``vertices``, and
        ``normals`` and ``uv`` when the call makes them, are refilled in place by the core,
        for callers that reuse the buffers across animation frames (a renderer's vertex
        buffers). Each must have exactly the shape and dtype of the new result, be
        C-contiguous and writeable and share no memory with an input, else a ValueError
        naming it (``out.vertices`` …). Returns a new :class:`Mesh` whose ``vertices``,
        ``normals`` and ``uv`` are those arrays; its ``faces`` (which depend only on the
        sizes) and other attributes are new. The values are those of the call without
        ``out``, bit for bit. If the call raises (or is interrupted by Ctrl-C), the
        contents of the arrays of ``out`` are unspecified.

    Consecutive samples closer than ``2⁻⁴⁰ ≈ 9.1e-13`` times their curve's size (its
    bounding box's largest side) are one point: they are merged into the first of them,
    which gets the ring (its ``point_data`` is the ring's; ``sample_of`` names it; the
    ``scale``/``twist``/``frames``/``tangents`` of the rows merged into it are not used).
    Errors name the rows as given.

    Returns
    -------
    Mesh
        ``vertices`` (V, 3), ``faces`` (F, 3), ``normals`` (V, 3) — normals of the smooth
        swept surface, tilted by a varying radius —, ``uv`` (V, 2) (u = spine arc length,
        v = profile arc length / perimeter), ``fold_over`` (spine rows), ``point_data``,
        ``cell_data`` (``"curve_id"`` per face for a bundle), and ``sample_of`` /
        ``curve_of``: the spine row and the curve of every vertex. Vertex ``k * m + j``
        (per spine) is profile vertex ``j`` on ring ``k``. The quads between rings are
        split along alternating diagonals (a checkerboard), so the volume of twisted sweeps
        converges at second order.

    Raises
    ------
    ValueError, TypeError
        Bad shapes, non-finite values (unless ``on_invalid="skip"``), a self-intersecting or
        zero-area profile, non-positive scale, frames that are not rotations or whose
        tangent at some row runs against the spine (a negative dot product with both
        chords at the row, with the one chord at an open end: a reversed frame, or frames
        of the reversed curve; the message names the row and, in a bundle, the curve),
        tangents of the wrong shape or of zero length, ``tangents``/``tangent_rule``
        together with ``frames`` (or with each other), and everything :func:`spinal.frames` refuses.

    Warns
    -----
    FoldOverWarning
        The surface folds over itself (spine rows; for a bundle also curve ids and the
        rows within each curve).
    SkippedCurvesWarning
        ``on_short="skip"`` left curves out.
    PrecisionWarning
        ``dtype=float32`` cannot resolve the profile: the coordinates' float32 spacing at the
        largest coordinate is over a tenth of the profile's smallest edge as swept (a thin
        tube far from the origin).
    """
    return _sweep_mesh(points, profile, frames, scale, twist, closed, caps, profile_closed,
                       miter_limit, split_seams, strict, lengths, offsets, "scale",
                       tangents, tangent_rule, dtype, normals, uv, point_data, on_short,
                       on_invalid, join, progress, turns, out)


def _out_buffers(out: object, normals: bool, uv: bool, inputs: list[tuple[str, object]]
                 ) -> tuple[np.ndarray | None, ...]:
    """The arrays of the Mesh ``out`` the sweep refills: ``(vertices, normals, uv)``, None
    for those the call does not make; the core checks their shapes, dtype, order and
    writeability (errors name ``out.vertices`` …)."""
    if out is None:
        return None, None, None
    if not isinstance(out, Mesh):
        raise TypeError(f"out: expected a spinal.Mesh (of an earlier sweep or tube of the same "
                        f"sizes), got {type(out).__name__}")
    arrays = [("vertices", out.vertices, True), ("normals", out.normals, normals),
              ("uv", out.uv, uv)]
    found: list[np.ndarray | None] = []
    for name, a, wanted in arrays:
        if not wanted:
            found.append(None)
            continue
        if a is None:
            raise ValueError(f"out.{name}: None, but the call makes {name} (pass a Mesh made "
                             f"with {name}=True, or {name}=False)")
        found.append(as_out(a, inputs, f"out.{name}"))
    return tuple(found)


def _sweep_frames(pts: np.ndarray, fr: np.ndarray | None, closed: bool, tg: np.ndarray | None, rule: TangentRule,
                  offs: np.ndarray, bundle: bool) -> tuple[np.ndarray | None, np.ndarray | None]:
    """The sweep's frames as the core takes them: ``(frames, None)`` for checked frames
    ``fr``, or ``(None, tangents)``: the RMF of :func:`spinal.frames` with the given
    (checked) tangents ``tg``, with tangents estimated by ``rule``, or (``tangents`` None)
    with its default tangents, which the core computes spine by spine as it sweeps (the
    same frames, bit for bit, without an ``(n, 3, 3)`` array of them)."""
    if fr is not None:
        if tg is not None or rule != DEFAULT_TANGENT_RULE:
            which = "tangents" if tg is not None else "tangent_rule"
            raise TypeError(f"{which}: not used with frames= (the frames' t column is the "
                            f"tangent)")
        return fr, None
    if tg is not None:
        if rule != DEFAULT_TANGENT_RULE:
            raise TypeError("tangent_rule: not used with tangents= (they replace the estimate)")
        return None, tg
    if rule != DEFAULT_TANGENT_RULE:
        return None, estimate_tangents(pts, closed=closed, method=rule,
                                       offsets=offs if bundle else None)
    return None, None


def _sweep_mesh(points: object, profile: object, frames: object, scale: object, twist: object,
                closed: object, caps: object, profile_closed: object, miter_limit: object,
                split_seams: object, strict: object, lengths: object, offsets: object,
                scale_arg: str, tangents: object = None,
                tangent_rule: object = DEFAULT_TANGENT_RULE, dtype: npt.DTypeLike = "float64",
                normals: object = True, uv: object = True, point_data: object = None,
                on_short: object = "raise", on_invalid: object = "raise",
                join: object = "round", progress: object = False, turns: object = 0,
                out: Mesh | None = None) -> Mesh:
    """:func:`sweep`, with the scale's errors naming ``scale_arg`` (called one level below
    the public function, which the warnings point at)."""
    progress = checked(progress)
    pts, offs, bundle = as_curves(points, lengths, offsets)
    n = pts.shape[0]
    closed = as_bool(closed, "closed")
    caps = as_bool(caps, "caps")
    profile_closed = as_bool(profile_closed, "profile_closed")
    split_seams = as_bool(split_seams, "split_seams")
    strict = as_bool(strict, "strict")
    single = _dtype(dtype)
    want_normals = as_bool(normals, "normals")
    want_uv = as_bool(uv, "uv")
    on_short = as_choice(on_short, "on_short", ("raise", "skip"))
    on_invalid = as_choice(on_invalid, "on_invalid", ("raise", "skip"))
    join = as_choice(join, "join", ("round", "bevel", "miter"))
    miter_limit = as_real(miter_limit, "miter_limit")  # the core checks the range
    turns = as_turns(turns, "turns")  # the core checks where it applies and the profile
    buffers = _out_buffers(out, want_normals, want_uv, [
        ("points", points), ("profile", profile), ("frames", frames), (scale_arg, scale),
        ("twist", twist), ("tangents", tangents), ("lengths", lengths),
        ("offsets", offsets)])
    if frames is not None and turns == int(turns) and turns != 0:
        raise TypeError("turns: with frames= only a half number is used (it says the frames "
                        "close up to a half turn); the given frames carry their whole turns")
    prof = as_float_array(profile, "profile")
    if prof.ndim != 2 or prof.shape[1] != 2:
        raise ValueError(f"profile: expected an array of shape (m, 2), got shape {prof.shape}")
    lens = np.diff(offs) if bundle and (np.diff(offs) >= 0).all() else None
    curves = offs.size - 1
    rule = as_choice(tangent_rule, "tangent_rule", TANGENT_RULES)
    fr = None if frames is None else as_frames(_joined(frames, "frames", offs, 3), "frames",
                                               rows=n)[0]
    tg = None
    if tangents is not None:
        tg = as_points(_joined(tangents, "tangents", offs, 2), "tangents")
        if tg.shape[0] != n:
            raise ValueError(f"tangents: expected shape ({n}, 3) to match points, got "
                             f"{tg.shape}")
    sc = _scale_rows(scale, scale_arg, n, lens)
    tw = None if twist is None else as_per_row(twist, "twist", n)
    pdata = _point_data(point_data, n, curves if bundle else None, lens)
    # curves too short to sweep: refused by the core (on_short="raise") or left out here
    # and curves with NaN/inf or too few distinct points (on_invalid)
    curve_ids, skipped = np.arange(curves), np.zeros(0, dtype=np.int64)
    keep_rows = None  # the given rows swept, where some are left out
    need = 3 if closed else 2
    counts: np.ndarray | None = lens if lens is not None else (
        np.array([n]) if not bundle else None)
    short = np.zeros(curves, dtype=bool)
    if on_short == "skip" and lens is not None:
        short = lens < need
        if short.any():
            warnings.warn(SkippedCurvesWarning(
                f"points: left out {int(short.sum())} curve(s) with fewer than {need} points "
                f"(on_short='skip'): {_ranges(np.flatnonzero(short))}; see "
                f"Mesh.skipped_curves", np.flatnonzero(short)), stacklevel=3)
    merge = None  # the plan of the rows kept, once made
    if on_invalid == "skip" and counts is not None:
        merge = _merge.plan(pts, offs, closed)
        status = merge.status
        nan, few = (status == _merge.NON_FINITE) & ~short, (status == _merge.TOO_FEW) & ~short
        if (nan | few).any():
            parts = [f"with NaN or inf: {_ranges(np.flatnonzero(nan))}"] if nan.any() else []
            if few.any():
                parts.append(f"with fewer than {need} distinct points: "
                             f"{_ranges(np.flatnonzero(few))}")
            warnings.warn(SkippedCurvesWarning(
                f"points: left out {int((nan | few).sum())} invalid curve(s) "
                f"(on_invalid='skip'): {'; '.join(parts)}; see Mesh.skipped_curves",
                np.flatnonzero(nan | few)), stacklevel=3)
            short = short | nan | few
    if short.any():
        assert counts is not None  # (curves are left out only when their rows are known)
        skipped = np.flatnonzero(short).astype(np.int64)
        keep_rows = np.repeat(~short, counts)
        pts, fr, tg, sc, tw = _cut(keep_rows, pts, fr, tg, sc, tw)
        curve_ids = curve_ids[~short]
        offs = np.concatenate([[0], np.cumsum(counts[~short])]).astype(np.int64)
        merge = None if merge is None else _merge.plan(pts, offs, closed)
    if buffers[0] is not None and merge is None:
        # the buffers are checked against the mesh of the rows kept: merge repeats first
        p = _merge.plan(pts, offs, closed)
        if p.merged and (p.status == _merge.VALID).all():
            merge = p
    if offs.size == 1:  # every curve left out
        mesh = Mesh(np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), np.zeros((0, 3)),
                    np.zeros((0, 2)), skipped_curves=skipped)
        if out is not None:
            mesh.vertices = fill_out(buffers[0], mesh.vertices, "out.vertices")
        mesh.point_data = {k: a[:0] for k, (a, _) in pdata.items()}
        mesh._n_rows, mesh._n_curves = n, curves
        return mesh
    given = _orig_offsets(lens, n)

    report = Reported(progress, "tube" if scale_arg == "radius" else "sweep", "row")

    def core(pts: np.ndarray, offs: np.ndarray, fr: np.ndarray | None, tg: np.ndarray | None,
             sc: np.ndarray, tw: np.ndarray | None) -> tuple[Any, ...]:
        fr, tg = _sweep_frames(pts, fr, closed, tg, rule, offs, bundle)
        with report:
            options: dict[str, object] = {
                "profile_closed": profile_closed, "closed": closed, "caps": caps,
                "miter_limit": miter_limit, "split_seams": split_seams, "scale_arg": scale_arg,
                "single": single, "index32": single, "normals": want_normals, "uv": want_uv,
                "tangents": tg, "join": join, "turns": float(turns),
                **dict(zip(("out_vertices", "out_normals", "out_uv"), buffers)),
            }
            return _core.sweep_mesh(pts, fr, sc, tw, offs, np.ascontiguousarray(prof), options,
                                    report.callback)

    def merged(p: _merge.Plan) -> None:
        # consecutive repeated samples: merged (a ring for the first row of each group)
        nonlocal pts, fr, tg, sc, tw, offs, keep_rows
        pts, fr, tg, sc, tw = _cut(p.keep, pts, fr, tg, sc, tw)
        offs = p.offsets
        if keep_rows is None:
            keep_rows = p.keep
        else:
            keep_rows[keep_rows] = p.keep

    try:
        if merge is not None and merge.merged:  # known already: cut before sweeping
            before = offs
            merged(merge)
        else:
            try:
                result = core(pts, offs, fr, tg, sc, tw)
                merge = None
            except _core.RepeatedPointsError as exc:
                merge, before = _merge.plan(pts, offs, closed), offs
                err = _merge.too_few_error(merge, offs, closed, bundle)
                if err is not None:
                    raise err from None
                if not merge.merged:  # nothing the plan would merge: refused as it is
                    raise ValueError(str(exc)) from None
                merged(merge)
        if merge is not None and merge.merged:
            try:
                result = core(pts, offs, fr, tg, sc, tw)
            except ValueError as exc:  # rows within the curves as given
                raise ValueError(_merge.as_given(str(exc), merge, before)) from None
    except ValueError as exc:
        if curve_ids.size == curves:
            raise
        # the core numbered the curves that were kept: back to the curves as given
        raise ValueError(_as_given(str(exc), curve_ids, given)) from None
    v, f, nrm, tex, folds, faces_per_curve, join_rows = result
    row_of = None if keep_rows is None else np.flatnonzero(keep_rows)
    if folds.size and row_of is not None:  # back to the rows as given
        folds = row_of[folds]
    rings, _ = _ring_layout(pts, offs, row_of, curve_ids, closed, split_seams, len(v),
                            join_rows)
    if folds.size:
        where = f"spine rows {_ranges(folds)}"
        fold_curves = None
        if bundle:
            starts = _orig_offsets(lens, n)
            fold_curves = np.searchsorted(starts, folds, side="right") - 1
            where += " (" + _by_curve(fold_curves, folds - starts[fold_curves]) + ")"
        msg = (
            f"the profile reaches past the spine's centre of curvature (the surface folds "
            f"over itself) on the segments starting at {where}; sample "
            f"the spine more densely there, reduce the profile, or smooth the spine"
        )
        if strict:
            raise ValueError(f"points: {msg}")
        local = None if fold_curves is None else folds - _orig_offsets(lens, n)[fold_curves]
        warnings.warn(FoldOverWarning(msg, folds, fold_curves, local), stacklevel=3)
    if single and len(v):
        _check_float32(pts, prof, sc)
    mesh = Mesh._of_sweep(v, f, nrm, tex, folds, rings, n, curves)
    mesh.skipped_curves = skipped
    if pdata:
        ring_sample, ring_curve, cols = mesh._ring_arrays()
        for k, (a, per_curve) in pdata.items():
            mesh.point_data[k] = np.repeat(a[ring_curve if per_curve else ring_sample], cols,
                                           axis=0)
    if bundle:  # each curve's faces follow those of the curve before it
        small = curves <= np.iinfo(np.int32).max
        mesh._lazy_curve_id(curve_ids.astype(np.int32 if small else np.int64), faces_per_curve)
    return mesh


def _check_float32(pts: np.ndarray, profile: np.ndarray, scale: np.ndarray) -> None:
    """Warn (:class:`PrecisionWarning`) where float32 coordinates cannot resolve the profile:
    their spacing at the largest coordinate (bounded by the spine's largest coordinate plus
    the profile's reach, so the vertices need not be read) over a tenth of the smallest
    profile edge times the smallest scale."""
    edges = np.linalg.norm(np.diff(np.r_[profile, profile[:1]], axis=0), axis=1)
    edges = edges[edges > 0]
    if not edges.size or not len(pts):
        return
    feature = float(edges.min() * np.abs(scale).min())
    reach = float(np.abs(profile).max() * np.abs(scale).max())
    largest = max(abs(float(pts.max())), abs(float(pts.min()))) + reach
    spacing = float(np.spacing(np.float32(largest)))
    if spacing > 0.1 * feature:
        warnings.warn(PrecisionWarning(
            f"dtype=float32: the coordinates' rounding ({spacing:.3g} at the largest "
            f"coordinate, {largest:.3g}) exceeds a tenth of the profile's "
            f"smallest edge as swept ({feature:.3g}): vertices merge or the cross-section is "
            f"distorted; use dtype=float64, or move the curves near the origin", spacing,
            feature), stacklevel=4)


def _as_given(msg: str, curve_ids: np.ndarray, starts: np.ndarray) -> str:
    """``msg`` with its ``curve c (rows a to b)`` (curve ``c`` of the curves kept) naming the
    curve and rows as given (``curve_ids[c]``; ``starts``: the given curves' first rows)."""
    def given(m: re.Match[str]) -> str:
        c = curve_ids[int(m.group(1))]
        return f"curve {c} (rows {starts[c]} to {max(starts[c + 1], 1) - 1})"
    return re.sub(r"curve (\d+) \(rows \d+ to \d+\)", given, msg, count=1)


def _orig_offsets(lens: np.ndarray | None, n: int) -> np.ndarray:
    return np.concatenate([[0], np.cumsum(lens)]) if lens is not None else np.array([0, n])


def _by_curve(curves: np.ndarray, rows: np.ndarray, most: int = 8) -> str:
    """'curve 3 rows 5–7; curve 9 row 0 …' (local rows), the first ``most`` curves."""
    ids = np.unique(curves)
    parts = []
    for c in ids[:most]:
        r = rows[curves == c]
        parts.append(f"curve {c} row{'s' if len(r) > 1 else ''} {_ranges(r)}")
    more = f"; and {len(ids) - most} more curves" if len(ids) > most else ""
    return "; ".join(parts) + more


def _per_row_or_curve(x: object, name: str, n: int, lens: np.ndarray | None, *, pair: bool
                      ) -> np.ndarray:
    """:func:`as_per_row`, also accepting one value per curve of a bundle, ``(C,)`` (or
    ``(C, 2)`` with ``pair``), repeated over the curve's rows."""
    a = as_float_array(x, name)
    if lens is not None and a.ndim >= 1 and len(a) == len(lens) != n and (
            a.shape == (len(lens),) or (pair and a.shape == (len(lens), 2))):
        a = np.repeat(a, lens, axis=0)
    return as_per_row(a, name, n, pair=pair)


def _per_curve_list(v: Any, lens: np.ndarray | None) -> Any:
    """A list (any sequence but an array) of one array per curve, as users hold values of
    streamlines (dipy's ``values_from_volume``): one row per point of each curve,
    concatenated, or one value (or ``(k,)`` row) per curve, stacked; anything else as
    given."""
    if lens is None or isinstance(v, (np.ndarray, str, bytes)) or not hasattr(v, "__len__"):
        return v
    if len(v) != len(lens) or not len(v):
        return v
    try:
        parts = [np.asarray(p) for p in v]
    except (TypeError, ValueError):
        return v
    if all(p.ndim in (1, 2) and len(p) == m for p, m in zip(parts, lens)) and \
            len({p.shape[1:] for p in parts}) == 1:
        return np.concatenate(parts)
    return v


def _point_data(data: object, n: int, curves: int | None, lens: np.ndarray | None = None
                ) -> dict[str, tuple[np.ndarray, bool]]:
    """``{name: (array, per_curve)}``: ``(n,)``/``(n, k)`` arrays per spine row, or for a
    bundle ``(C,)``/``(C, k)`` per curve, or a list of one ``(n_c,)``/``(n_c, k)`` array per
    curve (``lens``: the curves' row counts)."""
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise TypeError(f"point_data: expected a dict of arrays, got {type(data).__name__}")
    out: dict[str, tuple[np.ndarray, bool]] = {}
    for k, v in data.items():
        if not isinstance(k, str):
            raise TypeError(f"point_data: keys must be strings, got {k!r}")
        if isinstance(v, (str, bytes)):
            raise TypeError(f"point_data[{k!r}]: expected a numeric array, got "
                            f"{type(v).__name__}")
        per = f"({n},) or ({n}, k) per spine row" + (
            f", or ({curves},) or ({curves}, k) per curve, or a list of one (n_c,) or "
            f"(n_c, k) array per curve" if curves is not None else "")
        try:
            a = np.asarray(_per_curve_list(v, lens))
        except ValueError:  # ragged
            raise ValueError(f"point_data[{k!r}]: expected {per}; got a ragged sequence whose "
                             f"arrays do not match the curves' rows") from None
        if a.dtype.kind not in "biuf":
            raise TypeError(f"point_data[{k!r}]: expected a numeric array, got dtype {a.dtype}")
        if a.ndim not in (1, 2) or len(a) not in (n, curves):
            raise ValueError(f"point_data[{k!r}]: expected {per}, got shape {a.shape}")
        out[k] = (a, len(a) != n)
    return out


def _joined(x: Any, name: str, offs: np.ndarray, ndim: int) -> Any:
    """Per-row data given as a list (any sequence but an array) of one array per curve, as
    ``points`` may be (``ndim``: of each array, 2 for tangents, 3 for frames), back to back;
    anything else as given."""
    if isinstance(x, (np.ndarray, str, bytes)) or not hasattr(x, "__len__") or not len(x):
        return x
    try:
        first = np.asarray(x[0])
    except (TypeError, ValueError, IndexError, KeyError):
        return x
    if first.ndim != ndim:
        return x
    parts = [as_float_array(a, f"{name}[{c}]") for c, a in enumerate(x)]
    lens = np.diff(offs)
    if len(parts) != len(lens) or any(len(a) != m for a, m in zip(parts, lens)):
        raise ValueError(f"{name}: a list of {len(parts)} arrays of "
                         f"{[len(a) for a in parts][:8]} rows does not match the curves of "
                         f"points ({len(lens)} curves of {list(lens[:8])} rows)")
    return np.concatenate(parts)


def _cut(keep: np.ndarray, pts: np.ndarray, fr: np.ndarray | None, tg: np.ndarray | None, sc: np.ndarray, tw: np.ndarray | None
         ) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None, np.ndarray, np.ndarray | None]:
    """The per-row inputs of a sweep on the rows ``keep`` (a scale of one row stays)."""
    def cut(a: np.ndarray | None) -> np.ndarray | None:
        return None if a is None else np.ascontiguousarray(a[keep])

    def rows(a: np.ndarray) -> np.ndarray:
        return np.ascontiguousarray(a[keep])
    return rows(pts), cut(fr), cut(tg), (rows(sc) if sc.shape[0] > 1 else sc), cut(tw)


def _ring_layout(pts: np.ndarray, offs: np.ndarray, row_of: np.ndarray | None,
                 curve_ids: np.ndarray, closed: bool, split_seams: bool, nv: int,
                 join_rows: np.ndarray | None = None
                 ) -> tuple[Callable[[], tuple[np.ndarray, np.ndarray, int]], np.ndarray]:
    """The stored rings of a sweep, as the core lays them out: per curve, one ring per
    distinct sample (a closed curve's repeated first point has none; split seams on a
    closed curve repeat its first ring at the end), then the extra rings of its corner
    joins (``join_rows``: the swept row of the corner of each, in order). ``row_of``: the
    given row of every row swept (None: the same). Returns a function giving
    ``(ring_sample, ring_curve, cols)`` (given rows and curves; O(rings) memory, so only
    built when asked for) and the first vertex of every curve ``(C + 1,)``."""
    lens = np.diff(offs)
    rings = lens.copy()
    if closed:
        a, b = pts[offs[:-1]], pts[offs[1:] - 1]
        d = np.abs(b - a).max(axis=1)
        scale = np.maximum(np.abs(a).max(axis=1), np.abs(b).max(axis=1))
        rings -= ((lens >= 2) & (d <= 8 * np.finfo(float).eps * scale)).astype(rings.dtype)
    stored = rings + int(closed and split_seams)
    if join_rows is not None and len(join_rows):
        join_rows = np.asarray(join_rows, dtype=np.int64)
        extra = np.bincount(np.searchsorted(offs, join_rows, side="right") - 1,
                            minlength=len(lens))
    else:
        join_rows, extra = None, np.zeros_like(stored)
    total = int((stored + extra).sum())
    cols = nv // total
    if cols * total != nv:
        raise RuntimeError("spinal: the sweep's vertex layout is not one ring per sample")
    starts = np.concatenate([[0], np.cumsum(stored + extra)])
    per_ring = functools.partial(_per_ring, offs[:-1], stored, rings, starts, row_of,
                                 curve_ids, cols, extra, join_rows)
    return per_ring, starts * cols


def _per_ring(row0: np.ndarray, stored: np.ndarray, rings: np.ndarray, starts: np.ndarray,
              row_of: np.ndarray | None, curve_ids: np.ndarray, cols: int,
              extra: np.ndarray | None = None, join_rows: np.ndarray | None = None
              ) -> tuple[np.ndarray, np.ndarray, int]:
    """``(ring_sample, ring_curve, cols)`` of :func:`_ring_layout` (a module-level function
    bound with :func:`functools.partial`, so meshes that hold it pickle)."""
    total = int(starts[-1])
    per = stored if extra is None else stored + extra
    local = np.arange(total) - np.repeat(starts[:-1], per)
    sample = np.repeat(row0, per) + local % np.repeat(rings, per)
    if join_rows is not None:
        sample[local >= np.repeat(stored, per)] = join_rows
    if row_of is not None:
        sample = row_of[sample]
    return (sample.astype(np.int64), np.repeat(curve_ids, per).astype(np.int64), cols)


def tube(
    points: Array | CurveBundle,
    radius: float | Array = 1.0,
    sides: int = 16,
    *,
    frames: Array | None = None,
    closed: bool = False,
    caps: bool = True,
    miter_limit: float = 4.0,
    split_seams: bool = False,
    strict: bool = False,
    lengths: Ints | None = None,
    offsets: Ints | None = None,
    tangents: Array | None = None,
    tangent_rule: TangentRule = "five_point_bounded",
    dtype: npt.DTypeLike = "float64",
    normals: bool = True,
    uv: bool = True,
    point_data: PointData | None = None,
    on_short: Literal["raise", "skip"] = "raise",
    on_invalid: Literal["raise", "skip"] = "raise",
    join: Literal["round", "bevel", "miter"] = "round",
    progress: ProgressArg = False,
    turns: float = 0,
    out: Mesh | None = None,
) -> Mesh:
    """A tube of the given radius around a spine: :func:`sweep` of a regular polygon with
    ``sides`` vertices on the unit circle (vertex ``j`` at angle ``2πj/sides`` from r
    towards s), scaled by ``radius``.

    The cross-section is the inscribed polygon, of area ``(sides/2) ρ² sin(2π/sides)``.
    ``radius``: scalar or (n,) positive values (one per spine row), or for a bundle (C,)
    (one per curve); the normals are tilted by the radius slope. ``sides``: 3 to 2**20.
    Other arguments (bundles as lists of curves, ``tangents``, ``tangent_rule``,
    ``dtype=numpy.float32``, ``normals``, ``uv``, ``point_data``, ``on_short``, ``on_invalid``,
    ``join``, ``progress``, ``turns``, ``out``) as in :func:`sweep`. The polygon of an even number of
    sides maps onto itself under a half turn (vertex ``j`` to ``j + sides/2``), so a closed
    tube takes half-integer ``turns`` (an odd number of sides raises ValueError naming
    ``turns``).
    """
    # the core sees only the polygon built here
    sides = as_int(sides, "sides", 3, MAX_SIDES, out_of_bounds=lambda x: (
        f"a tube needs at least 3 sides, got {x}" if x < 3
        else f"at most {MAX_SIDES:,} (2**20) sides, got {x:,}"))
    if as_turns(turns, "turns") != int(turns) and sides % 2:
        raise ValueError(f"turns: a half number of turns ({turns}) needs a tube of an even "
                         f"number of sides (its polygon turned by π maps onto itself), got "
                         f"sides={sides}")
    a = 2 * np.pi * np.arange(sides) / sides
    profile = np.stack([np.cos(a), np.sin(a)], axis=1)
    # the core checks the radius' values, naming radius
    return _sweep_mesh(points, profile, frames, radius, None, closed, caps, True, miter_limit,
                       split_seams, strict, lengths, offsets, "radius", tangents, tangent_rule,
                       dtype, normals, uv, point_data, on_short, on_invalid, join, progress,
                       turns, out=out)
