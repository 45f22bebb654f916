"""Argument conversion shared by the public functions.

Every check raises ``TypeError`` (not numbers at all) or ``ValueError`` (numbers of the
wrong shape or value) with a message that starts with the argument's name.
"""

from __future__ import annotations

import numbers
from typing import Any

import numpy as np


def as_float_array(x: Any, name: str) -> np.ndarray:
    """``x`` as a float64 ndarray (a new array or a read-only view; never written to)."""
    if isinstance(x, (str, bytes)):
        raise TypeError(f"{name}: expected an array of real numbers, got {type(x).__name__}")
    try:
        arr = np.asarray(x)
    except (ValueError, TypeError) as exc:  # ragged nested lists
        raise ValueError(f"{name}: cannot be read as an array ({exc})") from None
    if arr.dtype.kind in "iuf":
        return arr.astype(np.float64, copy=False)
    if arr.dtype.kind == "O":
        try:
            return arr.astype(np.float64)
        except (ValueError, TypeError):
            pass
    raise TypeError(
        f"{name}: expected an array of real numbers, got dtype {arr.dtype}"
        + (" (complex values are not accepted)" if arr.dtype.kind == "c" else "")
    )


def as_points(x: Any, name: str = "points") -> np.ndarray:
    """An ``(n, 3)`` C-contiguous float64 array."""
    arr = as_float_array(x, name)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(f"{name}: expected an array of shape (n, 3), got shape {arr.shape}")
    return np.ascontiguousarray(arr)


def as_int(x: Any, name: str) -> int:
    if isinstance(x, bool) or not isinstance(x, numbers.Integral):
        raise TypeError(f"{name}: expected an integer, got {type(x).__name__}")
    return int(x)


def as_bool(x: Any, name: str) -> bool:
    if not isinstance(x, (bool, np.bool_)):
        raise TypeError(f"{name}: expected True or False, got {type(x).__name__}")
    return bool(x)


def as_choice(x: Any, name: str, choices: tuple[str, ...]) -> str:
    if not isinstance(x, str):
        raise TypeError(f"{name}: expected a string, one of {choices}, got {type(x).__name__}")
    if x not in choices:
        raise ValueError(f"{name}: unknown value {x!r}; expected one of {choices}")
    return x
