"""Argument conversion for steered frames: ``spinal.frames`` with ``constraints=``,
``twist_rule=``, ``guide=`` or ``previous=``, and ``spinal.frames_in_time``. The maths is in
the Rust core (``src/frames/constraints.rs``, ``guide.rs``, ``time.rs``)."""

from __future__ import annotations

import numbers
from collections.abc import Mapping
from typing import Any

import numpy as np

from ._validate import as_choice, as_float_array, as_real, as_turns

TWIST_RULES = ("arc_length", "min_angular_speed")


def _orientation_rows(vals: np.ndarray, name: str
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(k, 3) vectors or (k, 3, 3) frames -> (vectors, frames, is_frame)."""
    k = vals.shape[0]
    if vals.ndim == 2 and vals.shape[1] == 3:
        return vals, np.zeros((k, 3, 3)), np.zeros(k, dtype=bool)
    if vals.ndim == 3 and vals.shape[1:] == (3, 3):
        return np.zeros((k, 3)), vals, np.ones(k, dtype=bool)
    raise ValueError(f"{name}: expected vectors (k, 3) or frames (k, 3, 3), got shape {vals.shape}")


def _one_curve(given: Any, rows: int, where: str
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The constraints of one curve: (local rows, vectors, frames, is_frame)."""
    name = "constraints"
    if given is None:
        return (np.zeros(0, np.int64), np.zeros((0, 3)), np.zeros((0, 3, 3)),
                np.zeros(0, dtype=bool))
    if isinstance(given, Mapping):
        keys, vecs, frames, kinds = [], [], [], []
        for key, val in given.items():
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
            if not -2**63 <= int(key) < 2**63:
                raise ValueError(f"{name}: row {int(key)} is out of range for a curve of "
                                 f"{rows} rows{where}")
            keys.append(int(key))
        idx = np.array(keys, dtype=np.int64)
        vec = np.array(vecs, dtype=float).reshape(-1, 3)
        frm = np.array(frames, dtype=float).reshape(-1, 3, 3)
        kind = np.array(kinds, dtype=bool)
    elif isinstance(given, tuple) and len(given) == 2:
        idx = np.asarray(given[0])
        if idx.ndim != 1 or (idx.size and idx.dtype.kind not in "iu"):
            raise TypeError(f"{name}: the indices of (indices, vectors) must be a 1-D array of "
                            f"integers{where}")
        _fits_int64(idx, name, f" for a curve of {rows} rows{where}")
        idx = idx.astype(np.int64)
        vals = as_float_array(given[1], name)
        if vals.shape[:1] != idx.shape:
            raise ValueError(f"{name}: {idx.size} indices but vectors of shape {vals.shape}"
                             f"{where}")
        vec, frm, kind = _orientation_rows(vals, name)
    else:
        raise TypeError(f"{name}: expected a mapping {{row: vector or frame}} or a pair "
                        f"(indices, vectors){where}, got {type(given).__name__}")
    idx = np.where(idx < 0, idx + rows, idx)
    bad = (idx < 0) | (idx >= rows)
    if bad.any():
        row = int(np.asarray(given[0] if isinstance(given, tuple) else list(given))[bad][0])
        raise ValueError(f"{name}: row {row} is out of range for a curve of {rows} rows{where}")
    return idx, vec, frm, kind


def _constraints(given: Any, offs: np.ndarray, bundle: bool
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Flattened constraints of all curves: (curves, rows, vectors, frames, is_frame)."""
    curves = offs.size - 1
    if given is None:
        parts = [(c, _one_curve(None, 0, "")) for c in range(0)]
    elif bundle:
        if isinstance(given, (Mapping, np.ndarray)) or not hasattr(given, "__len__") \
                or len(given) != curves:
            raise ValueError(f"constraints: with lengths/offsets, expected a list of {curves} "
                             "entries (one mapping, (indices, vectors) pair or None per curve)")
        parts = [(c, _one_curve(s, int(offs[c + 1] - offs[c]), f" (curve {c})"))
                 for c, s in enumerate(given)]
    else:
        parts = [(0, _one_curve(given, int(offs[1]), ""))]
    cc = [np.full(p[0].size, c, np.int64) for c, p in parts]

    def cat(xs: list[np.ndarray], shape: int | tuple[int, ...]) -> np.ndarray:
        return np.ascontiguousarray(np.concatenate(xs)) if xs else np.zeros(shape)

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
        _fits_int64(a, "turns", "")
        return np.ascontiguousarray(a, dtype=np.float64)
    # one count: whole, or half (the closing twist of a closed curve; the core checks where)
    return np.array([as_turns(turns, "turns")], dtype=np.float64)


def _fits_int64(a: np.ndarray, name: str, context: str) -> None:
    """Refuse unsigned values that int64 would wrap (2**63 and up), naming ``name``."""
    if a.size and a.dtype.kind == "u" and a.max() > np.iinfo(np.int64).max:
        raise ValueError(f"{name}: {int(a.max())} is out of range{context}")


def guide_rows(guide: Any, rows: int) -> np.ndarray | None:
    """``guide`` as a C-contiguous (1, 3) or (rows, 3) array, or None."""
    if guide is None:
        return None
    g = as_float_array(guide, "guide")
    if g.shape == (3,):
        g = g[None, :]
    elif g.shape != (rows, 3):
        raise ValueError(f"guide: expected shape (3,) or ({rows}, 3) (one vector per "
                         f"sample), got {g.shape}")
    # a direction: each row divided by its largest component, so that its length (1e-200 or
    # 1e300 alike) does not reach the core's squares; zero rows stay zero (no guide there)
    big = np.abs(g).max(axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        g = np.where((big > 0) & np.isfinite(big), g / np.where(big > 0, big, 1.0), g)
    return np.ascontiguousarray(g)


def previous_frames(previous: Any, rows: int, what: str = "the frames of the same curve at "
                    "the previous time step") -> np.ndarray | None:
    """``previous`` as a C-contiguous (rows, 3, 3) array, or None."""
    if previous is None:
        return None
    prev = as_float_array(previous, "previous")
    if prev.shape != (rows, 3, 3):
        raise ValueError(f"previous: expected shape ({rows}, 3, 3) ({what}), got {prev.shape}")
    return np.ascontiguousarray(prev)


#: The names of the values returned by :func:`steering` (the keys of the core's ``steering``).
STEERING = ("turns", "con_curves", "con_rows", "con_vectors", "con_frames", "con_is_frame",
            "twist_rule", "guide", "guide_weight", "guide_tolerance", "guide_axis", "previous",
            "guide_previous", "previous_weight")


def steering(constraints: object, twist_rule: object, turns: object, guide: object,
             guide_weight: object, guide_tolerance: object, previous: object,
             offs: np.ndarray, bundle: bool, rows: int, guide_sign: str = "follow",
             guide_previous: np.ndarray | None = None, previous_weight: float = 1.0
             ) -> tuple[object, ...]:
    """The steering arguments of :func:`spinal.frames` as the core takes them: the turns,
    the five constraint arrays, the rule, the guide, its weight, tolerance and whether its
    rows are axes (``guide_sign="free"``), previous, the previous frames' ``r`` columns as a
    second target of the guide (``(rows, 3)`` or None) and their weight."""
    twist_rule = as_choice(twist_rule, "twist_rule", TWIST_RULES)
    axis = as_choice(guide_sign, "guide_sign", ("follow", "free")) == "free"
    before = None if guide_previous is None else np.ascontiguousarray(guide_previous)
    return (_turns(turns), *_constraints(constraints, offs, bundle), twist_rule,
            guide_rows(guide, rows), as_real(guide_weight, "guide_weight"),
            as_real(guide_tolerance, "guide_tolerance"), axis, previous_frames(previous, rows),
            before, as_real(previous_weight, "previous_weight"))
