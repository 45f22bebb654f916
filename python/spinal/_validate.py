"""Argument conversion shared by the public functions: one helper per kind of argument.

These coerce types and shapes (dtype, number of dimensions, shape, Python types, choices of
a string): array-likes become C-contiguous float64 arrays of the shape the core expects;
booleans must be ``bool``; integers must fit a 64-bit integer (counts within their bounds);
scalars that no core check sees must be finite and within their range. Values of arrays
(NaN/inf, lengths, repeated points, rotation matrices, …) are checked once, by the Rust
core, whose messages name the Python argument as well.

Every check raises ``TypeError`` (not numbers at all) or ``ValueError`` (numbers of the
wrong shape) with a message that starts with the argument's name.
"""

from __future__ import annotations

import numbers
from collections.abc import Callable, Iterable
from typing import Any, TypeVar

import numpy as np

_S = TypeVar("_S", bound=str)


def as_float_array(x: Any, name: str) -> np.ndarray:
    """``x`` as a float64 ndarray (a new array or a read-only view; never written to)."""
    if isinstance(x, (str, bytes)):
        raise TypeError(f"{name}: expected an array of real numbers, got {type(x).__name__}")
    try:
        arr = np.asarray(x)
    except (ValueError, TypeError) as exc:  # ragged nested lists
        raise ValueError(f"{name}: cannot be read as an array ({exc})") from None
    if arr.dtype.kind in "iuf":
        arr = arr.astype(np.float64, copy=False)
        # an unaligned buffer (pickle protocol 5 out-of-band data, as Dask and multiprocessing
        # deliver arrays) is copied: the core reads aligned float64 only
        return arr if arr.flags.aligned else arr.copy()
    if arr.dtype.kind == "O":
        try:
            return arr.astype(np.float64)
        except (ValueError, TypeError):
            pass
        if arr.ndim == 0:
            hint = _object_hint(x)
            if hint:
                raise TypeError(f"{name}: expected an array of real numbers, got a {hint}")
    raise TypeError(
        f"{name}: expected an array of real numbers, got dtype {arr.dtype}"
        + (" (complex values are not accepted)" if arr.dtype.kind == "c" else "")
    )


def _object_hint(x: Any) -> str:
    """For a mesh or polyline object passed where an array is expected: what it is and
    which of its arrays to pass ('' for other objects)."""
    kind = f"{type(x).__module__.split('.')[0]}.{type(x).__name__}"
    if kind in ("trimesh.Trimesh", "spinal.Mesh"):
        return f"{kind}; pass its vertices (mesh.vertices), or the mesh itself where a " \
               f"mesh is expected (deform, stamp, fields.mesh_curl)"
    if kind == "trimesh.Path3D":
        return f"{kind}; pass the points of one polyline (path.discrete[0])"
    if kind.startswith(("pyvista.", "vtkmodules.")):
        return f"{kind}; pass its points (data.points), or for the lines of a PolyData " \
               f"a list of one (n, 3) array per line"
    return ""


def as_points(x: Any, name: str = "points") -> np.ndarray:
    """An ``(n, 3)`` C-contiguous float64 array."""
    arr = as_float_array(x, name)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(f"{name}: expected an array of shape (n, 3), got shape {arr.shape}")
    return np.ascontiguousarray(arr)


def as_frames(x: Any, name: str = "frames", rows: int | None = None) -> tuple[np.ndarray, bool]:
    """An ``(n, 3, 3)`` C-contiguous float64 array (a single ``(3, 3)`` frame becomes one row)
    and whether the input was a single frame. ``rows``: the required ``n`` (then only
    ``(rows, 3, 3)`` is accepted)."""
    f = as_float_array(x, name)
    if rows is not None:
        if f.shape != (rows, 3, 3):
            raise ValueError(f"{name}: expected shape ({rows}, 3, 3) to match points, "
                             f"got {f.shape}")
        return np.ascontiguousarray(f), False
    single = f.ndim == 2
    if single:
        f = f[None]
    if f.ndim != 3 or f.shape[1:] != (3, 3):
        raise ValueError(f"{name}: expected shape (3, 3) or (n, 3, 3), got {np.shape(x)}")
    return np.ascontiguousarray(f), single


def as_vector(x: Any, name: str, width: int = 3) -> np.ndarray:
    """A ``(width,)`` C-contiguous float64 array."""
    v = as_float_array(x, name)
    if v.shape != (width,):
        raise ValueError(f"{name}: expected shape ({width},), got {v.shape}")
    return np.ascontiguousarray(v)


def as_per_row(x: Any, name: str, n: int, *, pair: bool = False) -> np.ndarray:
    """A scalar, ``(n,)`` or (``pair``) ``(n, 2)`` argument broadcast to ``(n,)`` or ``(n, 2)``."""
    a = as_float_array(x, name)
    if a.ndim == 0:
        a = np.full(n, float(a))
    if a.shape == (n,):
        return np.ascontiguousarray(np.stack([a, a], axis=1) if pair else a)
    if pair and a.shape == (n, 2):
        return np.ascontiguousarray(a)
    expect = f"a scalar, ({n},)" + (f" or ({n}, 2)" if pair else "")
    raise ValueError(f"{name}: expected {expect}, got shape {a.shape}")


def as_offsets(rows: int, lengths: Any, offsets: Any) -> tuple[np.ndarray, bool]:
    """CSR-style offsets ``(C + 1,)`` int64 of a bundle given by ``lengths`` or ``offsets``
    (neither: one curve of ``rows`` rows), and whether the call is a bundle. Only the types
    are checked here; the core checks the values (non-negative lengths adding up to the
    rows, offsets from 0)."""
    if lengths is not None and offsets is not None:
        raise TypeError("lengths, offsets: pass one of them, not both")
    if lengths is None and offsets is None:
        return np.array([0, rows], dtype=np.int64), False
    name = "lengths" if lengths is not None else "offsets"
    arr = np.asarray(lengths if lengths is not None else offsets)
    if arr.dtype.kind not in "iu" or arr.ndim != 1:
        raise TypeError(f"{name}: expected a 1-D array of integers, got {arr.dtype} {arr.shape}")
    # the values, named as given (the core checks the offsets it is handed again)
    if arr.size and arr.dtype.kind == "u" and arr.max() > np.iinfo(np.int64).max:
        raise ValueError(f"{name}: {int(arr.max())} is out of range")
    arr = arr.astype(np.int64)
    if lengths is not None:
        neg = np.flatnonzero(arr < 0)
        if neg.size:
            raise ValueError(f"{name}: must be non-negative, curve {neg[0]} has length "
                             f"{arr[neg[0]]}")
        if int(arr.sum(dtype=object)) != rows:
            raise ValueError(f"{name}: the curves cover {int(arr.sum(dtype=object))} rows but "
                             f"the input has {rows}")
        arr = np.concatenate([[0], np.cumsum(arr)]).astype(np.int64)
    elif arr.size:
        if arr[0] != 0:
            raise ValueError(f"{name}: must start at 0, got {arr[0]}")
        down = np.flatnonzero(np.diff(arr) < 0)
        if down.size:
            c = down[0]
            raise ValueError(f"{name}: must never decrease, got {arr[c + 1]} after {arr[c]} "
                             f"(curve {c})")
        if arr[-1] != rows:
            raise ValueError(f"{name}: the last offset is {arr[-1]} but the input has {rows} "
                             f"rows")
    return np.ascontiguousarray(arr), True


def is_curve_list(x: Any) -> bool:
    """Whether ``x`` is a sequence of curves (a list or tuple of ``(n_i, 3)`` arrays, nibabel's
    ``ArraySequence``, ...) rather than one ``(n, 3)`` array-like: not an ndarray, and its
    first item is two-dimensional (nibabel's ArraySequence, even empty)."""
    if isinstance(x, (np.ndarray, str, bytes)) or not hasattr(x, "__len__"):
        return False
    if not hasattr(x, "__iter__") and not hasattr(x, "__getitem__"):
        return False
    if type(x).__name__ == "ArraySequence":
        return True
    try:
        first = next(iter(x))
        return np.ndim(first) == 2
    except (StopIteration, TypeError, ValueError):
        return False


def as_curves(x: Any, lengths: Any = None, offsets: Any = None,
              name: str = "points") -> tuple[np.ndarray, np.ndarray, bool]:
    """The rows ``(N, 3)`` float64 (C-contiguous), the CSR offsets ``(C + 1,)`` int64 and
    whether the call is a bundle, from either one ``(n, 3)`` array-like with optional
    ``lengths``/``offsets`` (see :func:`as_offsets`) or a sequence of ``(n_i, 3)`` arrays of
    any real dtype (a list, a tuple, nibabel's ``ArraySequence``, ...): curve ``c`` is
    ``x[c]``, empty and one-row curves included."""
    if not is_curve_list(x):
        pts = as_points(x, name)
        offs, bundle = as_offsets(pts.shape[0], lengths, offsets)
        return pts, offs, bundle
    if lengths is not None or offsets is not None:
        raise TypeError(f"lengths, offsets: not accepted with a sequence of curves as {name} "
                        f"(the curves' lengths come from the sequence)")
    parts = []
    for c, item in enumerate(x):
        a = as_float_array(item, f"{name}[{c}]")
        if a.size == 0:
            a = a.reshape(0, 3)
        if a.ndim != 2 or a.shape[1] != 3:
            raise ValueError(f"{name}[{c}]: expected an array of shape (n, 3), got shape "
                             f"{a.shape}")
        parts.append(a)
    lens = np.array([len(a) for a in parts], dtype=np.int64)
    pts = np.concatenate(parts) if parts else np.zeros((0, 3))
    offs = np.concatenate([[0], np.cumsum(lens)]).astype(np.int64)
    return np.ascontiguousarray(pts, dtype=np.float64), offs, True


def as_real(x: Any, name: str) -> float:
    """A Python float from a real number (not a bool): the type only, any value."""
    if isinstance(x, bool) or not isinstance(x, numbers.Real):
        if isinstance(x, np.ndarray) and x.shape == () and x.dtype.kind in "iuf":
            x = x.item()
        else:
            raise TypeError(f"{name}: expected a real number, got {type(x).__name__}")
    return float(x)


def as_finite(x: Any, name: str, minimum: float | None = None,
              maximum: float | None = None) -> float:
    """A finite Python float (for values that no core check sees), within
    ``[minimum, maximum]`` when given."""
    v = as_real(x, name)
    if not np.isfinite(v):
        raise ValueError(f"{name}: must be finite, got {v}")
    if minimum is not None and v < minimum:
        raise ValueError(f"{name}: must be >= {minimum}, got {v}")
    if maximum is not None and v > maximum:
        raise ValueError(f"{name}: must be <= {maximum}, got {v}")
    return v


def as_positive(x: Any, name: str) -> float:
    """A finite Python float > 0."""
    v = as_finite(x, name)
    if not v > 0:
        raise ValueError(f"{name}: must be positive, got {v}")
    return v


#: Integers reach the core as 64-bit values.
INT64_MIN, INT64_MAX = -(2**63), 2**63 - 1

#: The most samples a count argument may ask for (``n`` points, parameters, steps): 10⁸
#: rows of float64 ``(n, 3)`` are 2.4 GB, beyond which a count is a typo, not a request.
MAX_SAMPLES = 100_000_000


def as_int(x: Any, name: str, minimum: int | None = None, maximum: int | None = None, *,
           out_of_bounds: Callable[[int], str] | None = None) -> int:
    """A Python int (not a bool) that fits a 64-bit integer, within ``[minimum, maximum]``
    when given. ``out_of_bounds(x)``, when given, words the error for a value outside the
    bounds (checked first, so a huge value gets the argument's own limits)."""
    if isinstance(x, bool) or not isinstance(x, numbers.Integral):
        raise TypeError(f"{name}: expected an integer, got {type(x).__name__}")
    v = int(x)
    if out_of_bounds is not None and (
            (minimum is not None and v < minimum) or (maximum is not None and v > maximum)):
        huge = "" if INT64_MIN <= v <= INT64_MAX else (
            " (out of the representable range of a 64-bit integer, too)")
        raise ValueError(f"{name}: {out_of_bounds(v)}{huge}")
    if not INT64_MIN <= v <= INT64_MAX:
        raise ValueError(f"{name}: {v} is out of the representable range of a 64-bit "
                         f"integer [-2**63, 2**63 - 1]")
    if minimum is not None and v < minimum:
        raise ValueError(f"{name}: must be >= {minimum}, got {v}")
    if maximum is not None and v > maximum:
        raise ValueError(f"{name}: must be <= {maximum}, got {v}")
    return v


def as_turns(x: Any, name: str = "turns") -> int | float:
    """A whole or half number of turns: an int for whole numbers (``2.0`` becomes ``2``, so
    whole numbers give the results of the int, bit for bit), a float ``k + 0.5`` for half
    numbers. Where a half number applies (the closing twist of a closed curve) is checked by
    the core; anything else raises, naming ``name``."""
    if isinstance(x, numbers.Integral) and not isinstance(x, (bool, np.bool_)):
        return as_int(x, name)
    if isinstance(x, (bool, np.bool_)) or not isinstance(x, numbers.Real):
        raise TypeError(f"{name}: expected a whole or half number of turns (e.g. 1, 0.5, "
                        f"-1.5), got {type(x).__name__}")
    v = float(x)
    if not np.isfinite(v) or 2 * v != round(2 * v) or abs(v) > 1e15:
        raise ValueError(f"{name}: expected a whole or half number of turns (e.g. 1, 0.5, "
                         f"-1.5), got {v!r}")
    return int(v) if v == round(v) else v


def as_bool(x: Any, name: str) -> bool:
    if not isinstance(x, (bool, np.bool_)):
        raise TypeError(f"{name}: expected True or False, got {type(x).__name__}")
    return bool(x)


def as_choice(x: Any, name: str, choices: tuple[_S, ...]) -> _S:
    if not isinstance(x, str):
        raise TypeError(f"{name}: expected a string, one of {choices}, got {type(x).__name__}")
    if x not in choices:
        raise ValueError(f"{name}: unknown value {x!r}; expected one of {choices}")
    return x


def as_out(out: object, inputs: Iterable[tuple[str, object]] = (),
           name: str = "out") -> np.ndarray | None:
    """A caller's output buffer ``out`` (or None), refused when it is not a NumPy array
    (TypeError) or shares memory with one of ``inputs`` (``(argument name, value)`` pairs;
    values that are not arrays, or lists of arrays, are passed over): a ValueError naming
    ``name`` and the argument. Its shape, dtype, order and writeability are checked where
    the result's shape is known (:func:`fill_out`, or the core)."""
    if out is None:
        return None
    if not isinstance(out, np.ndarray):
        raise TypeError(f"{name}: expected a NumPy array, got {type(out).__name__}")
    for arg, value in inputs:
        values = value if isinstance(value, (list, tuple)) else [value]
        for v in values:
            if isinstance(v, np.ndarray) and np.may_share_memory(out, v):
                raise ValueError(f"{name}: shares memory with {arg} (an output must not "
                                 f"overlap an input)")
    return out


def fill_out(out: np.ndarray | None, result: np.ndarray, name: str = "out") -> np.ndarray:
    """``result`` written into the caller's ``out`` (as the core checks it: exactly
    ``result``'s shape and dtype, C-contiguous, writeable; else a ValueError naming
    ``name``), which is returned; ``result`` itself when ``out`` is None."""
    if out is None or out is result:
        return result
    want = f"{name}: expected a C-contiguous writeable {result.dtype} array of shape"
    if out.dtype != result.dtype:
        raise ValueError(f"{want} {result.shape}, got a {out.dtype} array of shape "
                         f"{out.shape}")
    if out.shape != result.shape:
        raise ValueError(f"{want} {result.shape}, got shape {out.shape}")
    if not out.flags.c_contiguous:
        raise ValueError(f"{name}: must be C-contiguous (np.ascontiguousarray makes a copy "
                         f"that is)")
    if not out.flags.writeable:
        raise ValueError(f"{name}: must be writeable")
    out[...] = result
    return out
