"""Steered frames: ``spinal.frames`` with ``constraints=``, ``twist_rule=``, ``guide=`` or
``previous=``, and :func:`frames_in_time`. The maths is in the Rust core
(``src/frames/constraints.rs``, ``guide.rs``, ``time.rs``)."""

from __future__ import annotations

import numbers
from collections.abc import Mapping
from typing import Any

import numpy as np

from . import _core
from ._validate import (
    as_bool,
    as_choice,
    as_float_array,
    as_int,
    as_offsets,
    as_points,
    as_real,
)
from .curves import Curve

TWIST_RULES = ("arc_length", "min_angular_speed")


def _orientation_rows(vals: np.ndarray, name: str):
    """(k, 3) vectors or (k, 3, 3) frames -> (vectors, frames, is_frame)."""
    k = vals.shape[0]
    if vals.ndim == 2 and vals.shape[1] == 3:
        return vals, np.zeros((k, 3, 3)), np.zeros(k, dtype=bool)
    if vals.ndim == 3 and vals.shape[1:] == (3, 3):
        return np.zeros((k, 3)), vals, np.ones(k, dtype=bool)
    raise ValueError(f"{name}: expected vectors (k, 3) or frames (k, 3, 3), got shape {vals.shape}")


def _one_curve(spec: Any, rows: int, where: str):
    """The constraints of one curve: (local rows, vectors, frames, is_frame)."""
    name = "constraints"
    if spec is None:
        return (np.zeros(0, np.int64), np.zeros((0, 3)), np.zeros((0, 3, 3)),
                np.zeros(0, dtype=bool))
    if isinstance(spec, Mapping):
        keys, vecs, frames, kinds = [], [], [], []
        for key, val in spec.items():
            if isinstance(key, bool) or not isinstance(key, numbers.Integral):
                raise TypeError(f"{name}: keys must be integer rows, got {key!r}{where}")
            a = as_float_array(val, name)
            if a.shape == (3,):
                vecs.append(a)
                frames.append(np.zeros((3, 3)))
                kinds.append(False)
            elif a.shape == (3, 3):
                vecs.append(np.zeros(3))
                frames.append(a)
                kinds.append(True)
            else:
                raise ValueError(f"{name}: row {int(key)}: expected a vector (3,) or a frame "
                                 f"(3, 3), got shape {a.shape}{where}")
            keys.append(int(key))
        idx = np.array(keys, dtype=np.int64)
        vec = np.array(vecs, dtype=float).reshape(-1, 3)
        frm = np.array(frames, dtype=float).reshape(-1, 3, 3)
        kind = np.array(kinds, dtype=bool)
    elif isinstance(spec, tuple) and len(spec) == 2:
        idx = np.asarray(spec[0])
        if idx.ndim != 1 or (idx.size and idx.dtype.kind not in "iu"):
            raise TypeError(f"{name}: the indices of (indices, vectors) must be a 1-D array of "
                            f"integers{where}")
        idx = idx.astype(np.int64)
        vals = as_float_array(spec[1], name)
        if vals.shape[:1] != idx.shape:
            raise ValueError(f"{name}: {idx.size} indices but vectors of shape {vals.shape}"
                             f"{where}")
        vec, frm, kind = _orientation_rows(vals, name)
    else:
        raise TypeError(f"{name}: expected a mapping {{row: vector or frame}} or a pair "
                        f"(indices, vectors){where}, got {type(spec).__name__}")
    idx = np.where(idx < 0, idx + rows, idx)
    bad = (idx < 0) | (idx >= rows)
    if bad.any():
        row = int(np.asarray(spec[0] if isinstance(spec, tuple) else list(spec))[bad][0])
        raise ValueError(f"{name}: row {row} is out of range for a curve of {rows} rows{where}")
    return idx, vec, frm, kind


def _constraints(spec: Any, offs: np.ndarray, bundle: bool):
    """Flattened constraints of all curves: (curves, rows, vectors, frames, is_frame)."""
    curves = offs.size - 1
    if spec is None:
        parts = [(c, _one_curve(None, 0, "")) for c in range(0)]
    elif bundle:
        if isinstance(spec, (Mapping, np.ndarray)) or not hasattr(spec, "__len__") \
                or len(spec) != curves:
            raise ValueError(f"constraints: with lengths/offsets, expected a list of {curves} "
                             "entries (one mapping, (indices, vectors) pair or None per curve)")
        parts = [(c, _one_curve(s, int(offs[c + 1] - offs[c]), f" (curve {c})"))
                 for c, s in enumerate(spec)]
    else:
        parts = [(0, _one_curve(spec, int(offs[1]), ""))]
    cc = [np.full(p[0].size, c, np.int64) for c, p in parts]
    cat = (lambda xs, shape: np.ascontiguousarray(np.concatenate(xs))
           if xs else np.zeros(shape))
    return (
        cat(cc, 0).astype(np.int64),
        cat([p[0] for _, p in parts], 0).astype(np.int64),
        cat([p[1] for _, p in parts], (0, 3)),
        cat([p[2] for _, p in parts], (0, 3, 3)),
        cat([p[3] for _, p in parts], 0).astype(bool),
    )


def _turns(turns: Any) -> np.ndarray:
    if isinstance(turns, (list, tuple, np.ndarray)):
        a = np.asarray(turns)
        if a.ndim != 1 or (a.size and a.dtype.kind not in "iu"):
            raise TypeError("turns: expected an integer or a 1-D sequence of integers (one per "
                            "twist interval)")
        return np.ascontiguousarray(a, dtype=np.int64)
    return np.array([as_int(turns, "turns")], dtype=np.int64)


def _orientation(x: Any, name: str, curves: int, bundle: bool):
    from ._frames import _orientation as orient
    return orient(x, name, curves, bundle)


def steered(points, tangents, method, initial, closed, end, turns, reflection, u, lengths,
            offsets, constraints, twist_rule, guide, guide_weight, guide_tolerance, previous,
            points_arg="points"):
    """The frames of :func:`spinal.frames` with its steering arguments."""
    from ._frames import METHODS, REFLECTIONS, _analytic

    method = as_choice(method, "method", METHODS)
    reflection = as_choice(reflection, "reflection", REFLECTIONS)
    twist_rule = as_choice(twist_rule, "twist_rule", TWIST_RULES)
    closed = as_bool(closed, "closed")
    turn_counts = _turns(turns)
    weight = as_real(guide_weight, "guide_weight")
    tolerance = as_real(guide_tolerance, "guide_tolerance")
    d1 = d2 = uu = None
    if isinstance(points, Curve):
        if tangents is not None:
            raise TypeError("tangents: not accepted with an analytic curve (its exact tangents "
                            "are used)")
        if lengths is not None or offsets is not None:
            raise TypeError("lengths, offsets: not accepted with an analytic curve")
        if reflection != "chord":
            raise ValueError("reflection: 'tangents' applies to sampled curves only")
        pts, uu, d1, d2 = _analytic(points, u)
        tgs = None
    else:
        if u is not None:
            raise TypeError("u: only used with an analytic curve from spinal.curves")
        pts = None if points is None else as_points(points, points_arg)
        tgs = None if tangents is None else as_points(tangents, "tangents")
        if pts is None and (tgs is None or reflection != "tangents"):
            raise TypeError("points: required (only reflection='tangents' works from tangents "
                            "alone)")
    rows = (pts if pts is not None else tgs).shape[0]
    offs, bundle = (as_offsets(rows, lengths, offsets) if uu is None
                    else (np.array([0, rows], dtype=np.int64), False))
    curves = offs.size - 1
    iv, if_ = _orientation(initial, "initial", curves, bundle)
    ev, ef = _orientation(end, "end", curves, bundle)
    if bundle and (offs[0] != 0 or offs[-1] != rows or np.any(np.diff(offs) < 0)):
        # let the core name the rule that is broken
        _core.frames_sampled(pts, tgs, offs, method, "five_point", False, closed, None, None,
                             None, None, 0, points_arg)
    cons = _constraints(constraints, offs, bundle)
    g = None
    if guide is not None:
        g = as_float_array(guide, "guide")
        if g.shape == (3,):
            g = g[None, :]
        elif g.shape != (rows, 3):
            raise ValueError(f"guide: expected shape (3,) or ({rows}, 3) (one vector per "
                             f"sample), got {g.shape}")
        g = np.ascontiguousarray(g)
    prev = None
    if previous is not None:
        prev = as_float_array(previous, "previous")
        if prev.shape != (rows, 3, 3):
            raise ValueError(f"previous: expected shape ({rows}, 3, 3) (the frames of the same "
                             f"curve at the previous time step), got {prev.shape}")
        prev = np.ascontiguousarray(prev)
    return _core.frames_steered(
        pts, tgs, offs, uu, d1, d2, method, reflection == "tangents", closed, iv, if_, ev, ef,
        turn_counts, *cons, twist_rule, g, weight, tolerance, prev, points_arg,
    )


def frames_in_time(
    points_t,
    tangents_t=None,
    *,
    method: str = "double_reflection",
    initial=None,
    closed: bool = False,
    turns: int = 0,
    reflection: str = "chord",
    previous=None,
) -> np.ndarray:
    r"""Frames of a curve moving in time that do not flicker: ``(T, n, 3, 3)``.

    ``points_t`` holds ``T`` time steps of the same curve, ``(T, n, 3)`` (same sample count
    at every step). Every step gets its rotation-minimising frame (computed in parallel over
    ``T``), turned about the tangents by the one angle ``c`` that brings it closest to the
    frames of the step before: ``c`` minimises ``Σ_i ‖R_t(c) U_i − P_i‖²`` (Frobenius; every
    sample counts the same), in closed form ``c = atan2(Σ s·P_r − r·P_s, Σ r·P_r + s·P_s)``.
    All RMFs of a curve differ only by such a constant turn (Zheng 2008, Cor. 4.1.3), so the
    frames stay rotation minimising along the curve and change in time only as much as the
    curve makes them (Ma 1996, §3.5.3, aligns the frames of similar curves by one rotation).
    Equivalent to calling :func:`frames` with ``previous=`` step by step.

    Parameters
    ----------
    points_t : array_like (T, n, 3)
        The curve at ``T`` time steps.
    tangents_t : array_like (T, n, 3), optional
        Tangents at every step (else estimated as in :func:`frames`).
    method, closed, turns, reflection
        As in :func:`frames` (a closed curve keeps its closing twist at every step).
    initial : array_like (3,) or (3, 3), optional
        The start of the first step (as in :func:`frames`); not with ``previous``.
    previous : array_like (n, 3, 3), optional
        Frames of the step before the first one (to continue a sequence).

    Returns
    -------
    ndarray (T, n, 3, 3) float64

    Raises
    ------
    ValueError
        As :func:`frames` (the message names the time step), a ``previous`` of another shape
        than ``(n, 3, 3)`` or not made of rotations.
    """
    from ._frames import METHODS, REFLECTIONS

    method = as_choice(method, "method", METHODS)
    reflection = as_choice(reflection, "reflection", REFLECTIONS)
    closed = as_bool(closed, "closed")
    turns = as_int(turns, "turns")
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
    steps, n = ref.shape[0], ref.shape[1]
    iv, if_ = _orientation(initial, "initial", 1, False)
    prev = None
    if previous is not None:
        prev = as_float_array(previous, "previous")
        if prev.shape != (n, 3, 3):
            raise ValueError(f"previous: expected shape ({n}, 3, 3) (the frames of the step "
                             f"before), got {prev.shape}")
        prev = np.ascontiguousarray(prev)
    flat = (lambda a: None if a is None else np.ascontiguousarray(a.reshape(-1, 3)))
    out = _core.frames_in_time(flat(p), flat(tg), steps, method, reflection == "tangents",
                               closed, iv, if_, turns, prev)
    return out.reshape(steps, n, 3, 3)
