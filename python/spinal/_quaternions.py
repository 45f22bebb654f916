"""The implementation of :mod:`spinal.quaternions` (see its documentation); the public names are
re-exported there."""

from __future__ import annotations

from typing import Literal, NamedTuple

import numpy as np
import numpy.typing as npt

from . import _core, _merge
from ._frames import frames
from ._types import Array, Float64Array, Int64Array
from ._validate import (
    as_bool,
    as_choice,
    as_finite,
    as_float_array,
    as_frames,
    as_int,
    as_points,
    as_turns,
    as_vector,
)


def _to_xyzw(q: np.ndarray, scalar_first: bool) -> np.ndarray:
    return np.ascontiguousarray(q[..., [1, 2, 3, 0]] if scalar_first else q)


def _from_xyzw(q: np.ndarray, scalar_first: bool) -> np.ndarray:
    return np.ascontiguousarray(q[..., [3, 0, 1, 2]]) if scalar_first else q


def _quats(x: Array, name: str, scalar_first: bool) -> tuple[np.ndarray, bool]:
    """(n, 4) xyzw array and whether the input was a single quaternion."""
    q = as_float_array(x, name)
    single = q.ndim == 1
    if single:
        q = q[None]
    if q.ndim != 2 or q.shape[1] != 4:
        raise ValueError(f"{name}: expected shape (4,) or (n, 4), got {np.shape(x)}")
    return _to_xyzw(q, scalar_first), single


def to_quaternions(
    frames: Array, *, scalar_first: bool = False, continuous: bool = True
) -> Float64Array:
    """Unit quaternions of frames: ``(n, 3, 3)`` → ``(n, 4)`` (a single ``(3, 3)`` → ``(4,)``).

    Shepperd's method: the largest of ``1 + tr R`` and ``1 + 2R_kk − tr R`` gives the
    square-rooted component, so no small divisor occurs (exact to round-off at half turns).
    ``continuous=True`` (default) makes the signs continuous along the rows: the first
    quaternion is canonical (``w ≥ 0``, like scipy's ``canonical=True``), every next one is
    negated if its dot product with the previous is negative. With ``continuous=False`` every
    row is canonical.

    Raises ValueError for a row that is not a rotation matrix (orthonormal to 1e-6,
    ``det = +1``; a reflection has no quaternion).
    """
    f, single = as_frames(frames)
    q = _core.quat_from_frames(f, as_bool(continuous, "continuous"))
    q = _from_xyzw(q, as_bool(scalar_first, "scalar_first"))
    return q[0] if single else q


def from_quaternions(quaternions: Array, *, scalar_first: bool = False) -> Float64Array:
    """Frames (rotation matrices, columns ``r, s, t``) of quaternions: ``(n, 4)`` →
    ``(n, 3, 3)``. Quaternions are normalised first; a zero or non-finite row is refused."""
    q, single = _quats(quaternions, "quaternions", as_bool(scalar_first, "scalar_first"))
    f = _core.quat_to_frames(q)
    return f[0] if single else f


def make_continuous(quaternions: Array, *, scalar_first: bool = False) -> Float64Array:
    """A copy with signs flipped so that consecutive quaternions have a non-negative dot
    product (the first made canonical, ``w ≥ 0``). The frames are unchanged."""
    sf = as_bool(scalar_first, "scalar_first")
    q, _ = _quats(quaternions, "quaternions", sf)
    return _from_xyzw(_core.quat_continuous(q), sf)


def slerp(q0: Array, q1: Array, u: float | Array, *, scalar_first: bool = False) -> Float64Array:
    """Spherical linear interpolation ``q(u)`` from ``q0`` (``u = 0``) to ``q1`` (``u = 1``)
    on the short arc (``q1`` is negated when ``q0·q1 < 0``): constant angular speed, the
    rotation of the frames turning about a fixed axis. ``q0``, ``q1``: ``(4,)`` or ``(k, 4)``;
    ``u``: scalar or ``(k,)`` (broadcast). Returns unit quaternions ``(k, 4)`` (or ``(4,)``)."""
    sf = as_bool(scalar_first, "scalar_first")
    a, s0 = _quats(q0, "q0", sf)
    b, s1 = _quats(q1, "q1", sf)
    uu = as_float_array(u, "u")
    if uu.ndim > 1:
        raise ValueError(f"u: expected a scalar or a 1-D array, got shape {uu.shape}")
    single = s0 and s1 and uu.ndim == 0
    try:
        k = np.broadcast_shapes((a.shape[0],), (b.shape[0],), uu.reshape(-1).shape)
    except ValueError:
        raise ValueError(
            f"q0, q1, u: cannot broadcast {a.shape[0]}, {b.shape[0]} and {uu.size} rows"
        ) from None
    a = np.ascontiguousarray(np.broadcast_to(a, (k[0], 4)))
    b = np.ascontiguousarray(np.broadcast_to(b, (k[0], 4)))
    uu = np.ascontiguousarray(np.broadcast_to(uu.reshape(-1), k))
    out = _from_xyzw(_core.quat_slerp(a, b, uu), sf)
    return out[0] if single else out


def slerp_frames(frames: Array, new_u: Array, key_u: Array | None = None) -> Float64Array:
    """Frames interpolated between key frames by slerp.

    ``frames`` ``(n, 3, 3)`` at the strictly increasing parameters ``key_u`` (default
    ``0, 1, …, n−1``; e.g. cumulative arc length of the key points), evaluated at
    ``new_u`` ``(k,)`` inside ``[key_u[0], key_u[-1]]``. Between two keys the frame turns
    at constant speed about a fixed axis (Ma's key frames for camera paths). Returns
    ``(k, 3, 3)``.
    """
    f, _ = as_frames(frames)
    n = len(f)
    ku = np.arange(n, dtype=float) if key_u is None else as_float_array(key_u, "key_u")
    if ku.shape != (n,):
        raise ValueError(f"key_u: expected shape ({n},) to match frames, got {ku.shape}")
    nu = as_float_array(new_u, "new_u").reshape(-1)
    return _core.quat_slerp_frames(f, np.ascontiguousarray(ku), np.ascontiguousarray(nu))


def _initial_r(initial: Array | None) -> np.ndarray | None:
    """The reference vector at row 0 as given: a (3,) vector or a frame's first column."""
    if initial is None:
        return None
    v = as_float_array(initial, "initial")
    if v.shape == (3, 3):
        v = v[:, 0]
    if v.shape != (3,):
        raise ValueError("initial: expected a (3,) vector or a (3, 3) frame")
    return np.ascontiguousarray(v)


def quaternion_frames(
    points: Array,
    tangents: Array | None = None,
    *,
    method: Literal["transport", "frenet"] = "transport",
    initial: Array | None = None,
    closed: bool = False,
    turns: float = 0,
    scalar_first: bool = False,
) -> Float64Array:
    r"""Frames along a sampled curve as a sign-continuous quaternion curve ``(n, 4)``.

    * ``method="transport"`` (default): discrete parallel transport written with
      quaternions (Ma §2.2.1). ``Δq_i = normalise(1 + T_i·T_{i+1}, T_i × T_{i+1})`` rotates
      ``T_i`` onto ``T_{i+1}`` about their common normal and ``Q_{i+1} = Δq_i Q_i``. These
      are the frames of ``spinal.frames(points, tangents, method="rotation")`` (2nd order
      accurate RMF), computed by an independent recurrence. ``closed=True``: the closing
      angle ``α`` (= :func:`spinal.closing_angle` with ``method="rotation"``, ``∮τ ds`` mod
      2π in the limit) plus ``2π·turns`` is spread linearly in arc length by body
      rotations about the tangent, ``Q_i ← Q_i (cos(a_i/2), 0, 0, sin(a_i/2))`` with
      ``a_i = α L_i/L``, so the frames close. (Ma's text applies the mismatch angle with the
      opposite sign, which doubles it.) A half number of ``turns`` (``0.5``, ``-1.5``;
      closed curves only) leaves them closing up to a half turn about the tangent, as in
      :func:`spinal.frames`.
    * ``method="frenet"``: the Frenet frame ``(N, B, T)`` of ``spinal.frames(points,
      method="frenet")`` (with its continuous fill at inflections and straight runs) as
      quaternions.

    ``tangents``: optional ``(n, 3)`` (normalised); default :func:`spinal.estimate_tangents`.
    ``initial``: reference vector (or frame) at row 0, default the one of
    :func:`spinal.frames`. A closed curve may repeat its first point at the end; that row
    then gets the frame carried once round the loop (after the correction), ``±q₀``: the
    sign tells whether the quaternion curve closes on S³ or ends at the antipode.
    Consecutive samples closer than ``2⁻⁴⁰`` of the curve's size are merged, as in
    :func:`spinal.frames`: their rows get the quaternion of the row they repeat.
    """
    method = as_choice(method, "method", ("transport", "frenet"))
    closed = as_bool(closed, "closed")
    sf = as_bool(scalar_first, "scalar_first")
    turns = as_turns(turns, "turns")
    pts = as_points(points, "points")
    if method == "frenet":  # the core refuses initial and turns for the Frenet frame
        f = frames(pts, tangents, method="frenet", closed=closed, initial=initial, turns=turns)
        return _from_xyzw(_core.quat_from_frames(f, True), sf)
    t = None
    if tangents is not None:
        t = as_float_array(tangents, "tangents")
        if t.shape != pts.shape:
            raise ValueError(f"tangents: expected shape {pts.shape} to match points, got {t.shape}")
    r0 = _initial_r(initial)

    def transport(pts: np.ndarray, offs: np.ndarray, t: np.ndarray) -> np.ndarray:
        n = len(pts)
        repeat = closed and n > 3 and np.array_equal(pts[0], pts[-1])
        core_pts = pts[:-1] if repeat else pts
        tc = None if t is None else np.ascontiguousarray(t[: len(core_pts)])
        return _core.quat_transport(np.ascontiguousarray(core_pts), tc, r0, closed, turns,
                                    repeat)[0]

    # consecutive repeated samples merged (their rows get the quaternion of the row they
    # repeat), as in spinal.frames
    offs = np.array([0, len(pts)], dtype=np.int64)
    return _from_xyzw(_merge.on_rows(transport, pts, offs, closed, False, (t,)), sf)


def quaternion_length(q: Array, *, closed: bool = False, scalar_first: bool = False) -> float:
    r"""Length of the quaternion curve on the unit sphere S³: ``Σ 2·atan2(|q_{i+1} − q_i|,
    |q_{i+1} + q_i|)`` with each pair sign-aligned (= ``Σ arccos|q_i·q_{i+1}|``), plus the
    closing arc when ``closed``. Half the total rotation angle of the frames; in the limit
    ``½∫|ω| ds``: ``½∫κ ds`` for parallel transport, ``½∫√(κ² + τ²) ds`` for Frenet (``π``
    per turn of any helix). Accepts ``(n, 4)`` quaternions or ``(n, 3, 3)`` frames."""
    a = as_float_array(q, "q")
    if a.ndim == 3:
        a = _core.quat_from_frames(as_frames(a, "q")[0], True)
    else:
        a, _ = _quats(a, "q", as_bool(scalar_first, "scalar_first"))
    # + 0.0: an empty sum is -0.0
    return float(_core.quat_path_length(a, as_bool(closed, "closed"))) + 0.0


def spin(a: Array, b: Array) -> Float64Array | float:
    """Signed angle (radians, in (−π, π]) that turns frame ``a``'s reference vector ``r``
    into frame ``b``'s about ``a``'s tangent — the twist between two frames with the same
    tangent (e.g. an RMF against the Frenet frame). ``a``, ``b``: ``(3, 3)`` or ``(n, 3, 3)``
    (one of them may be a single frame). Both must be finite rotation matrices whose
    tangents (third columns) agree within 1e-3 rad; otherwise ``ValueError`` names the
    argument and the frame.
    """
    fa, sa = as_frames(a, "a")
    fb, sb = as_frames(b, "b")
    ang = _core.quat_spin(fa, fb)
    return float(ang[0]) if (sa and sb) else ang


def camera_frames(
    points: Array,
    *,
    up: Array | None = None,
    mode: Literal["transport", "up"] = "transport",
    closed: bool = False,
    turns: int = 0,
    bank: float | Array | None = None,
    tangents: Array | None = None,
    singular_angle: float = 1e-3,
) -> Float64Array:
    r"""Camera orientations for flying along a path: ``(n, 3, 3)`` camera-to-world rotations
    with columns ``(right, up, back)``, ``back = −gaze`` (the OpenGL/VTK convention: the
    camera looks along its −z). With pyvista: ``position = points[i]``, ``focal_point =
    points[i] − cam[i][:, 2]``, ``view_up = cam[i][:, 1]``.

    The gaze is the path's unit tangent. The up vector:

    * ``mode="transport"`` (default): the rotation-minimising frame of
      :func:`spinal.frames` started from ``up`` (projected onto the first normal plane;
      default world +z, or spinal's default where the path starts vertical) — the frame a
      viewer flies with, no roll from one sample to the next; on ``closed`` paths the closing
      angle is spread so that the camera returns to its start orientation.
    * ``mode="up"``: a level horizon: up is the world ``up`` (default +z) projected onto the
      normal plane, ``right = gaze × up`` stays horizontal. Where the path runs within
      ``singular_angle`` radians of vertical the projection is undefined; those runs are
      carried by the rotation-minimising frame from the last regular sample and the
      mismatch to the next regular sample is spread linearly in arc length. (Passing through
      the vertical, a level-horizon camera must turn by about π about its gaze.)

    ``bank``: optional roll angles (scalar or ``(n,)``, radians) about the gaze, right-handed
    about the direction of travel: positive turns up towards right (a roll to the right).
    Consecutive repeated samples (a pause in a track; closer than ``2⁻⁴⁰`` of its size) are
    merged, as in :func:`spinal.frames`: their rows get the camera of the row they repeat.
    """
    mode = as_choice(mode, "mode", ("transport", "up"))
    closed = as_bool(closed, "closed")
    pts = as_points(points, "points")
    n = len(pts)
    t = None
    if tangents is not None:
        t = as_float_array(tangents, "tangents")
        if t.shape != pts.shape:
            raise ValueError(f"tangents: expected shape {pts.shape}, got {t.shape}")
        t = np.ascontiguousarray(t)
    u = None if up is None else as_vector(up, "up")
    b = None
    if bank is not None:
        b = as_float_array(bank, "bank")
        b = np.broadcast_to(b, (n,)) if b.ndim == 0 else b
        if b.shape != (n,):
            raise ValueError(f"bank: expected a scalar or shape ({n},), got {b.shape}")
        b = np.ascontiguousarray(b)
    singular = as_finite(singular_angle, "singular_angle", 0.0, np.pi / 2)
    turns = as_int(turns, "turns")

    def camera(pts: np.ndarray, offs: np.ndarray, t: np.ndarray, b: np.ndarray) -> np.ndarray:
        t, uu, vertical, regular = _core.camera_inputs(pts, t, u, b, closed, mode == "up",
                                                       singular)
        if mode == "transport":
            init = None if vertical else uu
            f = frames(pts, t, initial=init, closed=closed, turns=turns)
        else:
            assert regular is not None  # (given in the "up" mode)
            f = _level_frames(pts, t, uu, regular, closed)
        # spinal frame (r, s, t) = (up, right, gaze), rolled by the bank about the gaze
        # (up' = cos b up + sin b (t × up)), then reordered to camera (right, up, −gaze)
        return _core.camera_orient(np.ascontiguousarray(f), b)

    # consecutive repeated samples (a pause in a GPS track) merged: their rows get the
    # camera of the row they repeat
    out: Float64Array = _merge.on_rows(camera, pts, np.array([0, n], dtype=np.int64), closed, False, (t, b))
    return out


def _rotate_about_t(f: np.ndarray, ang: float) -> np.ndarray:
    c, s = np.cos(ang), np.sin(ang)
    g = f.copy()
    g[:, :, 0] = c * f[:, :, 0] + s * f[:, :, 1]
    g[:, :, 1] = c * f[:, :, 1] - s * f[:, :, 0]
    return g


def _angle_about(a: np.ndarray, b: np.ndarray, t: np.ndarray) -> float:
    return float(np.arctan2(np.cross(a, b) @ t, a @ b))


def _level_frames(pts: np.ndarray, t: np.ndarray, u: np.ndarray, regular: np.ndarray,
                  closed: bool) -> np.ndarray:
    """Level-horizon frames; ``regular``: the rows where ``u`` projects onto the normal plane
    (checked by the core: at least one)."""
    n = len(pts)
    f = _core.camera_level(t, u, regular)
    if regular.all():
        return f
    shift = 0
    if closed:  # start the bookkeeping at a regular row
        shift = int(np.argmax(regular))
        pts, t, f, regular = (np.roll(a, -shift, axis=0) for a in (pts, t, f, regular))
    bad = np.flatnonzero(~regular)
    runs = np.split(bad, np.flatnonzero(np.diff(bad) > 1) + 1)
    for run in runs:
        a, b = run[0], run[-1]  # singular rows a..b
        if a > 0 and b + 1 < n:  # between regular rows: carry and meet the end frame
            sub = frames(pts[a - 1 : b + 2], t[a - 1 : b + 2], initial=f[a - 1],
                         end=f[b + 1])
            f[a : b + 1] = sub[1:-1]
        elif a > 0:  # trailing run: carry from the last regular row
            f[a:] = frames(pts[a - 1 :], t[a - 1 :], initial=f[a - 1])[1:]
        else:  # leading run: carry backwards from the first regular row
            sub = frames(pts[: b + 2], t[: b + 2])
            sub = _rotate_about_t(sub, _angle_about(sub[-1][:, 0], f[b + 1][:, 0], t[b + 1]))
            f[: b + 1] = sub[:-1]
    if shift:
        f = np.roll(f, shift, axis=0)
    return f


class WalkResult(NamedTuple):
    """Result of :func:`walk_mesh`: the state after every move (row 0 is the start) and the
    polyline of the walk with every edge crossing (``k`` moves, ``m`` path points).

    Attributes
    ----------
    points : ndarray (k+1, 3) float64
        The walker's position after every move (mesh units).
    faces : ndarray (k+1,) int64
        The face it stands on.
    frames : ndarray (k+1, 3, 3) float64
        Its frame, columns ``e₁`` (right), ``e₂`` (up), ``e₃`` (face normal).
    stopped : ndarray (k,) bool
        The move ended early at a boundary edge.
    path : ndarray (m, 3) float64
        The start, every edge crossing and every move end, in order.
    path_faces : ndarray (m,) int64
        The face entered at each path point.
    path_moves : ndarray (m,) int64
        The move each path point belongs to (0 = the start).
    """

    points: Float64Array
    faces: Int64Array
    frames: Float64Array
    stopped: npt.NDArray[np.bool_]
    path: Float64Array
    path_faces: Int64Array
    path_moves: Int64Array


def _faces(faces: Array) -> np.ndarray:
    fa = np.asarray(faces)
    if fa.ndim != 2 or fa.shape[1] != 3 or not (fa.size == 0 or np.issubdtype(fa.dtype, np.integer)):
        raise ValueError(f"faces: expected an integer array of shape (F, 3), got {fa.shape} "
                         f"{fa.dtype}")
    return np.ascontiguousarray(fa, dtype=np.int64)


def walk_mesh(
    vertices: Array,
    faces: Array,
    face: int,
    point: Array,
    moves: Array,
    *,
    direction: Array | None = None,
) -> WalkResult:
    r"""Walk on a triangle mesh with a frame (Ma 1996 §4.2.1).

    The walker starts at ``point`` (projected onto face ``face``; must lie inside it) with
    the frame ``e₃`` = the face normal (from the winding), ``e₁`` = ``direction`` projected
    onto the face (default: the face's first edge), ``e₂ = e₃ × e₁``. Each move ``(dx, dy)``
    of ``moves`` ``(k, 2)`` goes the distance ``|(dx, dy)|`` in the direction ``dx e₁ +
    dy e₂`` along the surface. At every edge the frame and the direction are rotated about
    the edge by the dihedral angle (the next face unfolded onto the current one), so the
    path is straight in the unfolded strip and the frame turns without twist; around a
    vertex it turns by the angle deficit ``2π − Σ angles``. A move stops early at a
    boundary edge (``stopped``). ``e₁, e₂, e₃`` are the camera-to-world axes of a camera
    looking straight down at the surface.

    Raises ValueError for out-of-range or degenerate faces, non-manifold edges (more than two
    faces), a start point off the face, non-finite values, and a move that would cross more
    than about 10⁸ edges (its length over the median edge length of the mesh); MemoryError,
    before the walk starts, when the crossing path of all the moves (about 72 bytes per
    crossing) cannot be allocated.
    """
    v = as_points(vertices, "vertices")
    fa = _faces(faces)
    p = as_vector(point, "point")
    d = None if direction is None else as_vector(direction, "direction")
    mv = as_float_array(moves, "moves")
    if mv.ndim == 1 and mv.shape == (2,):
        mv = mv[None]
    if mv.ndim != 2 or mv.shape[1] != 2:
        raise ValueError(f"moves: expected shape (k, 2), got {mv.shape}")
    out = _core.walk_mesh(np.ascontiguousarray(v), fa,
                          as_int(face, "face"), np.ascontiguousarray(p), d,
                          np.ascontiguousarray(mv))
    return WalkResult(*out)


class WalksResult(NamedTuple):
    """Result of :func:`walk_mesh_many`: the state of every walker after every move (``w``
    walkers, ``k`` moves each; move 0 is the start).

    Attributes
    ----------
    points : ndarray (w, k+1, 3) float64
        Positions (mesh units).
    faces : ndarray (w, k+1) int64
        The faces they stand on.
    frames : ndarray (w, k+1, 3, 3) float64
        Frames, columns ``e₁`` (right), ``e₂`` (up), ``e₃`` (face normal).
    stopped : ndarray (w, k) bool
        The move ended early at a boundary edge.
    """

    points: Float64Array
    faces: Int64Array
    frames: Float64Array
    stopped: npt.NDArray[np.bool_]


def walk_mesh_many(
    vertices: Array,
    faces: Array,
    face: Array,
    points: Array,
    moves: Array,
    *,
    directions: Array | None = None,
) -> WalksResult:
    r"""Many walkers on one triangle mesh at once, in parallel: :func:`walk_mesh` for every
    walker, with the edge adjacency built once.

    ``face`` ``(w,)`` and ``points`` ``(w, 3)`` give the starts, ``moves`` is ``(w, k, 2)``
    (or ``(k, 2)``, the same moves for every walker), ``directions`` ``None``, ``(3,)`` or
    ``(w, 3)`` the first directions. Walker ``i`` gives exactly the states of
    ``walk_mesh(vertices, faces, face[i], points[i], moves[i], direction=directions[i])``
    (the crossing polylines are not returned). Errors name the walker.
    """
    v = as_points(vertices, "vertices")
    fa = _faces(faces)
    fc = np.asarray(face)
    if fc.ndim != 1 or not (fc.size == 0 or np.issubdtype(fc.dtype, np.integer)):
        raise ValueError(f"face: expected an integer array of shape (w,), got {fc.shape} "
                         f"{fc.dtype}")
    w = len(fc)
    p = as_float_array(points, "points")
    if p.shape != (w, 3):
        raise ValueError(f"points: expected shape ({w}, 3) (one start per face), got {p.shape}")
    d = None
    if directions is not None:
        d = as_float_array(directions, "directions")
        if d.shape == (3,):
            d = np.broadcast_to(d, (w, 3))
        if d.shape != (w, 3):
            raise ValueError(f"directions: expected shape (3,) or ({w}, 3), got {d.shape}")
        d = np.ascontiguousarray(d)
    mv = as_float_array(moves, "moves")
    if mv.ndim == 2 and mv.shape[1] == 2:
        mv = np.broadcast_to(mv, (w,) + mv.shape)
    if mv.ndim != 3 or mv.shape[0] != w or mv.shape[2] != 2:
        raise ValueError(f"moves: expected shape ({w}, k, 2) or (k, 2), got {mv.shape}")
    k = mv.shape[1]
    out = _core.walk_mesh_many(np.ascontiguousarray(v), fa,
                               np.ascontiguousarray(fc, dtype=np.int64), np.ascontiguousarray(p),
                               d, np.ascontiguousarray(mv.reshape(w * k, 2)), k)
    return WalksResult(*out)
