"""The arguments of :mod:`spinal.fields` and its tools of sampled shapes: distances sampled on a
grid (of an array or of a closed mesh), their B-spline coefficients, and the fields built on
them by the core."""

from __future__ import annotations

import numbers

import numpy as np

from . import _core
from ._core import Field
from ._mesh import mesh_arrays
from ._progress import Progress, checked
from ._types import Array
from ._validate import (
    as_bool,
    as_float_array,
    as_int,
    as_positive,
    as_real,
    as_vector,
)


def _opt(x: object, name: str) -> float | None:
    return None if x is None else as_real(x, name)


def _power(x: object) -> int:
    return as_int(x, "falloff_power")


def _spline_prefilter(values: np.ndarray) -> np.ndarray:
    """Coefficients (n + 2 per axis, one ghost layer each side) of the natural cubic B-spline
    interpolating ``values`` on a unit grid: per axis ``c_0 = d_0``, ``c_{n−1} = d_{n−1}``,
    ``c_{i−1} + 4c_i + c_{i+1} = 6d_i`` inside, ghosts ``c_{−1} = 2c_0 − c_1`` (zero second
    derivative at the end nodes). Solved in the core, line by line in parallel."""
    return _core.field_grid_coefficients(np.ascontiguousarray(values, dtype=np.float64))


def _grid_field(values: np.ndarray, origin: np.ndarray, h: float, velocity: Array,
                center: Array | None, reach: float | None, blend: str, moving: bool,
                name: str) -> Field:
    """The tool of a sampled distance: the default centre and reach from the samples, the
    B-spline coefficients, then the core (which checks the spacing against the reach and that
    the support stays inside the grid)."""
    u = as_vector(velocity, "velocity")
    coef, c, r = _grid_spline(values, origin, h, center, reach)
    return _core.field_grid(coef, {"origin": origin, "spacing": h, "velocity": u, "center": c,
                                   "reach": r, "blend": blend,
                                   "moving": as_bool(moving, "moving"), "name": name})


def _grid_spline(values: np.ndarray, origin: np.ndarray, h: float, center: Array | None,
                 reach: float | None) -> tuple[np.ndarray, np.ndarray, float]:
    """The B-spline coefficients of sampled distances with the tool's centre (default: the
    volume-fraction centroid of the inside) and reach (default: its bounding radius)."""
    if not (values <= 0).any():
        raise ValueError("grid: no node is inside the tool (all distances are positive)")
    if center is None:
        # volume-fraction weights of the nodes' cells, clamp(1/2 − d/h, 0, 1)
        w = np.clip(0.5 - values / h, 0.0, 1.0)
        idx = np.argwhere(w > 0)
        ww = w[w > 0]
        c = origin + (idx * ww[:, None]).sum(axis=0) / ww.sum() * h
    else:
        c = as_vector(center, "center")
    if reach is None:
        idx = np.argwhere(values <= 0)
        nodes = origin + idx * h
        r = float((np.linalg.norm(nodes - c, axis=1) - values[values <= 0]).max())
    else:
        r = as_real(reach, "reach")
    return _spline_prefilter(values), c, r


def _sdf_samples(grid: Array, origin: Array, spacing: float
                 ) -> tuple[np.ndarray, np.ndarray, float]:
    """The samples of ``sdf_tool``/``sdf_curl`` as a float64 array, checked, with the origin
    and spacing."""
    a = as_float_array(grid, "grid")
    if a.ndim != 3 or min(a.shape) < 8:
        raise ValueError(f"grid: expected a 3-D array with at least 8 nodes per axis, got "
                         f"shape {a.shape}")
    if not np.isfinite(a).all():
        i = tuple(int(v) for v in np.argwhere(~np.isfinite(a))[0])
        raise ValueError(f"grid: value at node {i} is not finite")
    if a.size > 300**3:
        raise ValueError(f"grid: {a.size} nodes is too many (at most 300³)")
    o = as_vector(origin, "origin")
    h = as_positive(spacing, "spacing")
    return np.array(a, dtype=np.float64), o, h


#: Grid nodes per slab of a mesh's sampled distance with progress reports (whole planes;
#: at least one plane), and at least this many per face of the mesh.
SLAB_NODES = 1 << 16


SLAB_PER_FACE = 32


# cells per reach that the blend region needs (the core refuses coarser grids, naming
# `spacing`; `mesh_tool` chooses its spacing and names `resolution`)
MIN_CELLS_PER_REACH = 4


def _closed_mesh(mesh: object) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Vertices, faces and the enclosed volume's centroid of a closed, outward-wound mesh
    (the core checks it, naming ``mesh``)."""
    V, F = mesh_arrays(mesh)
    _, centroid = _core.mesh_closed_centroid(V, F)
    return V, F, np.asarray(centroid)


def _mesh_samples(mesh: object, reach: float | None, resolution: int, center: Array | None,
                  progress: object) -> tuple[np.ndarray, np.ndarray, float, np.ndarray, float]:
    """The signed distance of a closed mesh sampled on the grid of :func:`mesh_tool`:
    samples, origin, spacing, centre and reach."""
    progress = checked(progress)
    V, F, centroid = _closed_mesh(mesh)
    c = centroid if center is None else as_vector(center, "center")
    rf = float(np.linalg.norm(V - c, axis=1).max()) if reach is None else as_real(reach, "reach")
    if not rf > 0:
        raise ValueError(f"reach: must be positive, got {rf}")
    if isinstance(resolution, bool) or not isinstance(resolution, numbers.Integral):
        raise TypeError(f"resolution: expected an integer, got {type(resolution).__name__}")
    res = int(resolution)
    if not 16 <= res <= 256:
        raise ValueError(f"resolution: must be in 16 … 256, got {res}")
    pad = 4
    lo, hi = V.min(axis=0), V.max(axis=0)
    h = float((hi - lo).max() + 2 * rf) / (res - 1 - 2 * pad)
    if not rf >= MIN_CELLS_PER_REACH * h:
        need = int(np.ceil(((hi - lo).max() + 2 * rf) / (rf / MIN_CELLS_PER_REACH))) + 2 * pad + 1
        raise ValueError(
            f"resolution: grid too coarse: spacing {h:.4g} must be at most reach/"
            f"{MIN_CELLS_PER_REACH} = {rf / MIN_CELLS_PER_REACH:.4g}; use resolution ≥ {need}")
    try:
        import igl
    except ImportError as e:  # pragma: no cover - libigl is a test dependency
        raise ImportError("mesh_tool: building the distance grid needs libigl (pip install "
                          "libigl); or sample the distance yourself and use "
                          "fields.sdf_tool") from e
    origin = lo - rf - pad * h
    shape = np.ceil((hi - lo + 2 * (rf + pad * h)) / h).astype(int) + 1
    axes = [origin[i] + h * np.arange(shape[i]) for i in range(3)]
    # with progress: slabs of whole x planes of at least SLAB_NODES nodes, and of at least
    # SLAB_PER_FACE nodes per face (libigl builds its tree of the faces again for every
    # call; this keeps that under a few per cent); each point's distance is its own, so the
    # slabs give the one call's values. Reports (and Ctrl-C) come between them.
    d = np.empty(tuple(shape))
    plane = int(shape[1] * shape[2])
    per = int(shape[0]) if progress is False else max(
        1, max(SLAB_NODES, SLAB_PER_FACE * len(F)) // plane)
    yz = np.stack(np.meshgrid(axes[1], axes[2], indexing="ij"), axis=-1).reshape(-1, 2)
    with Progress(progress, d.size, "distance grid", "node") as bar:
        for i0 in range(0, int(shape[0]), per):
            xs = axes[0][i0:i0 + per]
            P = np.column_stack([np.repeat(xs, plane), np.tile(yz, (len(xs), 1))])
            d[i0:i0 + len(xs)] = igl.signed_distance(
                P, V, F, sign_type=igl.SIGNED_DISTANCE_TYPE_PSEUDONORMAL)[0].reshape(
                    len(xs), shape[1], shape[2])
            bar.update((i0 + len(xs)) * plane)
    return d, origin, h, c, rf


def _motion(velocity: Array | None, angular_velocity: Array | None, pivot: Array | None
            ) -> tuple[np.ndarray | None, np.ndarray | None, np.ndarray | None]:
    return (None if velocity is None else as_vector(velocity, "velocity"),
            None if angular_velocity is None else as_vector(angular_velocity, "angular_velocity"),
            None if pivot is None else as_vector(pivot, "pivot"))


def _grid_curl(values: np.ndarray, origin: np.ndarray, h: float, center: Array | None,
               reach: float | None, velocity: Array | None, angular_velocity: Array | None,
               pivot: Array | None, falloff_power: int, moving: bool, name: str) -> Field:
    u, w, p = _motion(velocity, angular_velocity, pivot)
    coef, c, r = _grid_spline(values, origin, h, center, reach)
    return _core.field_grid_curl(coef, {"origin": origin, "spacing": h, "center": c,
                                        "reach": r, "velocity": u, "angular_velocity": w,
                                        "pivot": p, "falloff_power": _power(falloff_power),
                                        "moving": as_bool(moving, "moving"), "name": name})
