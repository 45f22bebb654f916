"""The arguments of :func:`spinal.frames` and :func:`spinal.frames_in_time` as the core takes
them: methods, orientations, sampled or analytic curves, guide and previous options."""


from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from . import _merge
from ._steer import guide_rows, previous_frames
from ._types import (
    FrameMethod,
    Reflection,
    TangentRule,
)
from ._validate import (
    MAX_SAMPLES,
    as_curves,
    as_finite,
    as_float_array,
    as_int,
    as_offsets,
    as_points,
    as_real,
    is_curve_list,
)
from .curves import Curve

METHODS: tuple[FrameMethod, ...] = ("double_reflection", "projection", "rotation", "frenet", "rk4", "rk4_phi", "torsion",
           "bisector")


REFLECTIONS: tuple[Reflection, ...] = ("chord", "tangents")


TANGENT_RULES: tuple[TangentRule, ...] = ("five_point_bounded", "five_point", "five_point_uniform", "circle")


DEFAULT_TANGENT_RULE = "five_point_bounded"


def _orientation(x: Any, name: str, curves: int, bundle: bool
                 ) -> tuple[np.ndarray | None, np.ndarray | None]:
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


def _analytic(curve: Curve, u: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Points, parameters and exact derivatives at the samples and midpoints."""
    if u is None:
        raise TypeError("u: required with an analytic curve (parameter values or a sample count)")
    if isinstance(u, (int, np.integer)) and not isinstance(u, bool):
        count = as_int(u, "u", 2, MAX_SAMPLES, out_of_bounds=lambda x: (
            f"a sample count must be at least 2 and at most {MAX_SAMPLES:,}, got {x}"))
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


def _third(curve: Curve, uu: np.ndarray, method: str) -> np.ndarray | None:
    """``x‴`` at the samples and midpoints for the torsion method (None for the others)."""
    if method != "torsion":
        return None
    full = np.empty(2 * uu.size - 1)
    full[0::2], full[1::2] = uu, 0.5 * (uu[:-1] + uu[1:])
    return np.ascontiguousarray(curve.d3(full))


def _sampled(points: object, tangents: object, reflection: str, lengths: object, offsets: object,
             points_arg: str = "points") -> tuple[np.ndarray | None, np.ndarray | None, np.ndarray, bool]:
    """Sampled points and tangents as the core takes them: ``(pts, tgs, offs, bundle)``, rows
    ``(N, 3)`` float64 (either may be ``None``), CSR offsets ``(C + 1,)`` and whether the
    call is a bundle; a sequence of ``(n_i, 3)`` curves (any real dtype, nibabel's
    ``ArraySequence``) is one bundle, as one array with ``lengths``/``offsets``."""
    if is_curve_list(points) or (points is None and is_curve_list(tangents)):
        # a sequence of curves: the rows back to back, the lengths from the sequence
        pts, offs, bundle = (None, None, True) if points is None else as_curves(
            points, lengths, offsets, points_arg)
        tgs = None
        if tangents is not None:
            tgs, toffs, _ = as_curves(tangents, None, None, "tangents")
            if offs is not None and not np.array_equal(toffs, offs):
                raise ValueError("tangents: the curves must have the lengths of points'")
            offs = toffs if offs is None else offs
    else:
        pts = None if points is None else as_points(points, points_arg)
        tgs = None if tangents is None else as_points(tangents, "tangents")
        offs = None
    ref = pts if pts is not None else tgs
    if ref is None or (pts is None and reflection != "tangents"):
        raise TypeError("points: required (only reflection='tangents' works from tangents alone)")
    rows = ref.shape[0]
    bundle = offs is not None
    if offs is None:
        offs, bundle = as_offsets(rows, lengths, offsets)
    return pts, tgs, offs, bundle


def _shape(method: str, closed: bool, iv: np.ndarray | None = None, if_: np.ndarray | None = None,
           ev: np.ndarray | None = None, ef: np.ndarray | None = None, **more: object) -> dict[str, object]:
    """The options of the core's frames calls (``spinal._core.frames_*``): the method, the
    default tangent rule, whether the curve is closed, the start and end orientations as
    vectors and frames, and any call-specific ``more``."""
    return {"method": method, "tangent_rule": DEFAULT_TANGENT_RULE, "closed": closed,
            "initial_vectors": iv, "initial_frames": if_, "end_vectors": ev, "end_frames": ef,
            **more}


def _guide_options(guide_weight: object, guide_tolerance: object) -> tuple[float, float]:
    """``guide_weight`` and ``guide_tolerance`` as floats, checked even when no guide or
    previous uses them (the same bounds as the core's)."""
    weight = as_real(guide_weight, "guide_weight")
    if not 0.0 < weight < np.inf:
        raise ValueError(f"guide_weight: must be a positive finite number, got {weight}")
    tolerance = as_finite(guide_tolerance, "guide_tolerance", 0.0)
    if not tolerance < np.pi / 2:
        raise ValueError(f"guide_tolerance: must be an angle in [0, π/2) radians, got "
                         f"{tolerance}")
    return weight, tolerance


def _previous_weight(previous_weight: object, guide_weight: float) -> float:
    """``previous_weight`` as a float (checked as ``guide_weight``); None: ``guide_weight``."""
    if previous_weight is None:
        return guide_weight
    weight = as_real(previous_weight, "previous_weight")
    if not 0.0 < weight < np.inf:
        raise ValueError(f"previous_weight: must be a positive finite number, got {weight}")
    return weight


def _signed_by(guide: object, previous: object, rows: int) -> np.ndarray:
    """The axis guide ``guide`` with every row's sign agreeing with the ``r`` column of
    ``previous`` (checked as :func:`frames` checks it): ``(rows, 3)``."""
    given = guide_rows(guide, rows)
    if given is None:
        raise TypeError("guide: required")  # (the callers pass it)
    prev = _previous_twist_guide(previous, rows)
    g = np.broadcast_to(given, (rows, 3))
    flip = np.einsum("ij,ij->i", g, prev) < 0
    return np.where(flip[:, None], -g, g)


def _skipped_warning(nan: np.ndarray, few: np.ndarray, closed: bool, what: str) -> None:
    from ._mesh import SkippedCurvesWarning

    msg = _merge.skipped_message("points", nan, few, bool(closed), what)
    warnings.warn(SkippedCurvesWarning(msg, np.union1d(nan, few)), stacklevel=3)


def _cut_rows(a: Any, keep: np.ndarray, n: int) -> Any:
    """A per-row argument (``n`` rows, or a list of one array per curve) on the rows kept;
    anything else (one vector for all rows, None) as given."""
    if a is None:
        return None
    if not isinstance(a, np.ndarray) and is_curve_list(a):
        a = np.concatenate([np.asarray(x, dtype=float) for x in a])
    arr = np.asarray(a, dtype=float)
    return arr[keep] if arr.ndim >= 2 and arr.shape[0] == n else a


def _cut_curves(a: Any, bad: np.ndarray, curves: int) -> Any:
    """A per-curve ``initial``/``end`` (``(C, 3)`` or ``(C, 3, 3)``) on the curves kept;
    one for all curves as given."""
    if a is None:
        return None
    arr = np.asarray(a, dtype=float)
    per_curve = arr.ndim == 3 or (arr.ndim == 2 and arr.shape != (3, 3))
    return np.delete(arr, bad, axis=0) if per_curve and arr.shape[0] == curves else a


def _previous_twist_guide(previous: object, rows: int) -> np.ndarray:
    """The ``r`` columns of ``previous`` (checked: one rotation per row) as a guide."""
    prev = previous_frames(previous, rows)
    if prev is None:
        raise TypeError("previous: required")  # (the callers pass it)
    m = prev
    err = np.abs(np.swapaxes(m, -1, -2) @ m - np.eye(3)).max(axis=(-2, -1))
    bad = np.flatnonzero(~(err < 1e-6) | ~(np.linalg.det(m) > 0))
    if bad.size:
        raise ValueError(f"previous: row {bad[0]} is not a rotation matrix (columns r, s, t "
                         f"orthonormal, det +1)")
    return np.ascontiguousarray(prev[:, :, 0])


def _time_steps(points_t: object, tangents_t: object
                ) -> tuple[np.ndarray | None, np.ndarray | None, int, int]:
    """``points_t``, ``tangents_t`` as float arrays ``(T, n, 3)`` (either may be None, not
    both), and ``T``, ``n``."""
    p = None if points_t is None else as_float_array(points_t, "points_t")
    tg = None if tangents_t is None else as_float_array(tangents_t, "tangents_t")
    ref = p if p is not None else tg
    if ref is None:
        raise TypeError("points_t: required")
    for a, name in ((p, "points_t"), (tg, "tangents_t")):
        if a is not None and (a.ndim != 3 or a.shape[2] != 3 or a.shape[0] < 1):
            raise ValueError(f"{name}: expected shape (T, n, 3), got {a.shape}")
    if p is not None and tg is not None and p.shape != tg.shape:
        raise ValueError(f"tangents_t: shape {tg.shape} does not match points_t {p.shape}")
    return p, tg, ref.shape[0], ref.shape[1]
