"""The triangle mesh returned by the sweeps, with conversions to trimesh and pyvista."""

from __future__ import annotations

import os
import pathlib
from collections.abc import Sequence
from typing import Any, Literal, overload

import numpy as np
import numpy.typing as npt

from . import _core, _files
from ._types import Array, Float64Array, Int64Array, PointData
from ._validate import as_float_array

__all__ = ["FoldOverWarning", "Mesh", "SkippedCurvesWarning", "mesh_arrays"]


class PrecisionWarning(UserWarning):
    """float32 output cannot resolve the swept profile: the rounding of the coordinates
    (their float32 spacing at the mesh's largest coordinate) is more than a tenth of the
    profile's smallest edge as swept, so vertices merge or the cross-section is distorted.
    ``spacing`` and ``feature`` hold the two lengths."""

    spacing: float
    feature: float

    def __init__(self, message: str, spacing: float, feature: float) -> None:
        super().__init__(message)
        self.spacing = spacing
        self.feature = feature

    def __reduce__(self) -> tuple[Any, ...]:
        message = self.args[0] if self.args else ""
        return type(self), (message, self.spacing, self.feature), self.__dict__


class FoldOverWarning(UserWarning):
    """The swept profile reaches past the spine's centre of curvature, so the surface folds
    over itself there. ``indices`` holds the spine rows that start the folded segments (rows
    of all curves back to back); for a bundle ``curves`` holds the curve of each and
    ``rows`` the row within that curve (None for a single spine)."""

    indices: Int64Array
    curves: Int64Array | None
    rows: Int64Array | None

    def __init__(
        self, message: str, indices: Int64Array, curves: Int64Array | None = None, rows: Int64Array | None = None
    ) -> None:
        super().__init__(message)
        self.indices = indices
        self.curves = curves
        self.rows = rows

    def __reduce__(self) -> tuple[Any, ...]:
        # the default (cls, args, state) would call cls(message) without indices; pickling
        # matters for process pools, which send exceptions (and recorded warnings) back
        message = self.args[0] if self.args else ""
        return type(self), (message, self.indices, self.curves, self.rows), self.__dict__


class SkippedCurvesWarning(UserWarning):
    """A sweep with ``on_short="skip"`` left out curves too short to sweep; ``curves`` holds
    their ids (also in ``Mesh.skipped_curves``)."""

    curves: Int64Array

    def __init__(self, message: str, curves: Int64Array) -> None:
        super().__init__(message)
        self.curves = curves

    def __reduce__(self) -> tuple[Any, ...]:
        message = self.args[0] if self.args else ""
        return type(self), (message, self.curves), self.__dict__


def signed_volume(V: np.ndarray, F: np.ndarray) -> float:
    """Signed volume ``Σ (a · (b × c)) / 6`` of the triangles ``F`` over vertices ``V``
    (divergence theorem; positive for a closed, outward-facing mesh), summed about the mean
    vertex so that a small mesh far from the origin keeps its digits."""
    return _core.mesh_volume(np.ascontiguousarray(V, dtype=np.float64),
                             np.ascontiguousarray(F, dtype=np.int64).reshape(-1, 3))


def volumes_at_scale(F: np.ndarray, reference: np.ndarray, *others: np.ndarray
                     ) -> tuple[int, list[float]]:
    """``(e, [volume of reference, volume of each other])`` of meshes sharing the faces ``F``,
    each taken on its vertices times ``2**-e``, the power of two that brings the largest
    coordinate of ``reference`` into [1, 2). Scaling by a power of two is exact, so ratios and
    differences of these volumes are those of the true volumes even where the true volumes
    overflow or underflow float64 (coordinates near 1e±110); ``ldexp(v, 3e)`` gives a volume
    back in the mesh's units."""
    largest = float(np.abs(reference).max(initial=0.0))
    e = int(np.frexp(largest)[1]) - 1 if largest > 0 else 0
    e = max(-1000, min(1000, e))
    return e, [signed_volume(np.ldexp(np.asarray(V, dtype=np.float64), -e), F)
               for V in (reference, *others)]


def mesh_arrays(mesh: object) -> tuple[Float64Array, Int64Array]:
    """``(vertices (V, 3) float64, faces (F, 3) int64)`` of a spinal.Mesh, a trimesh.Trimesh or a
    ``(vertices, faces)`` pair, named ``mesh`` in errors."""
    given: Any = mesh
    if isinstance(given, tuple) and len(given) == 2:
        vertices, faces = given
    elif hasattr(given, "vertices") and hasattr(given, "faces"):
        vertices, faces = given.vertices, given.faces
    else:
        raise TypeError("mesh: expected a spinal.Mesh, a trimesh.Trimesh or (vertices, faces)")
    V = np.ascontiguousarray(as_float_array(vertices, "mesh"), dtype=np.float64)
    F = np.asarray(faces)
    if V.ndim != 2 or V.shape[1] != 3:
        raise ValueError(f"mesh: vertices must have shape (n, 3), got {V.shape}")
    if not np.isfinite(V).all():
        raise ValueError("mesh: vertices must be finite")
    if F.ndim != 2 or F.shape[1] != 3 or F.dtype.kind not in "iu":
        raise ValueError(f"mesh: faces must be an (m, 3) integer array, got {F.shape} {F.dtype}")
    F = np.ascontiguousarray(F, dtype=np.int64)
    if not F.flags.aligned:  # e.g. from a pickle protocol 5 buffer
        F = F.copy()
    if len(F) and (F.min() < 0 or F.max() >= len(V)):
        raise ValueError("mesh: face indices out of range")
    return V, F


def _as_faces(faces: Array, n: int) -> np.ndarray:
    """``faces`` as an ``(F, 3)`` int64 (or int32) array with every index in ``0..n``."""
    if isinstance(faces, (str, bytes)):
        raise TypeError(f"faces: expected an (F, 3) array of integers, got {type(faces).__name__}")
    try:
        F = np.asarray(faces)
    except (ValueError, TypeError) as exc:
        raise ValueError(f"faces: cannot be read as an array ({exc})") from None
    if F.size == 0:
        F = F.reshape(0, 3)
    if F.dtype.kind not in "iu":
        raise TypeError(f"faces: expected integer vertex indices, got dtype {F.dtype}")
    if F.ndim != 2 or F.shape[1] != 3:
        raise ValueError(f"faces: expected an array of shape (F, 3), got shape {F.shape}")
    if F.dtype not in (np.int32, np.int64):
        if F.dtype.kind == "u" and F.size and F.max() > np.iinfo(np.int64).max:
            raise ValueError(f"faces: vertex index {F.max()} out of range (there are {n} "
                             f"vertices)")
        F = F.astype(np.int64)
    _core.mesh_check_faces(np.ascontiguousarray(F), n)
    return F


def _rows_or_none(x: Array | None, name: str, n: int, width: int) -> np.ndarray | None:
    if x is None:
        return None
    a = (x if isinstance(x, np.ndarray) and x.dtype == np.float32
         else as_float_array(x, name))
    if a.shape != (n, width):
        raise ValueError(f"{name}: expected shape ({n}, {width}) (one row per vertex), got "
                         f"{a.shape}")
    _core.mesh_check_finite(np.ascontiguousarray(a), name)
    return a


@overload
def _index_array(x: Array | None, name: str, n: int | None = None,
                 none: Literal[False] = False) -> Int64Array: ...
@overload
def _index_array(x: Array | None, name: str, n: int | None, none: Literal[True]
                 ) -> Int64Array | None: ...
def _index_array(x: Array | None, name: str, n: int | None = None, none: bool = False
                 ) -> Int64Array | None:
    if x is None:
        return None if none else np.zeros(0, dtype=np.int64)
    a = np.asarray(x)
    if a.size == 0:
        a = a.reshape(0)
    if a.dtype.kind not in "iu" or a.ndim != 1:
        raise TypeError(f"{name}: expected a 1-D array of integers, got {a.dtype} {a.shape}")
    if n is not None and len(a) != n:
        raise ValueError(f"{name}: expected one entry per vertex ({n}), got {len(a)}")
    return a.astype(np.int64, copy=False)


def _attributes(data: object, name: str, n: int) -> dict[str, np.ndarray]:
    """A dict of ``(n,)`` / ``(n, k)`` numeric arrays (``name`` in errors)."""
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise TypeError(f"{name}: expected a dict of arrays, got {type(data).__name__}")
    out = {}
    for k, v in data.items():
        if not isinstance(k, str):
            raise TypeError(f"{name}: keys must be strings, got {k!r}")
        a = np.asarray(v)
        if a.dtype.kind not in "biuf" or a.ndim not in (1, 2) or len(a) != n:
            raise ValueError(f"{name}[{k!r}]: expected a numeric ({n},) or ({n}, k) array, "
                             f"got {a.dtype} {a.shape}")
        out[k] = a
    return out


def _rows_of(m: Mesh) -> int:
    """Spine rows a mesh stands for (for offsetting ``sample_of`` when joining)."""
    n = getattr(m, "_n_rows", None)
    if n is not None:
        out: int = n
        return out
    s = m.sample_of
    return int(s.max()) + 1 if s is not None and len(s) else 0


def _curves_of(m: Mesh) -> int:
    n = getattr(m, "_n_curves", None)
    if n is not None:
        out: int = n
        return out
    c = m.curve_of
    return int(c.max()) + 1 if c is not None and len(c) else 0


class Mesh:
    """A triangle mesh: what :func:`spinal.sweep` and :func:`spinal.tube` return.

    ``Mesh(vertices, faces, ...)`` checks its arrays (shapes, integer faces with indices in
    ``0..V``); errors name the argument.

    Attributes
    ----------
    vertices : ndarray (V, 3) float64 (or float32)
    faces : ndarray (F, 3) int64 (or int32)
        Vertex indices, counter-clockwise seen from outside (the right-hand normal points
        outwards on closed and capped sweeps).
    normals : ndarray (V, 3) float64 (or float32), or None
        Unit normals of the smooth swept surface at the vertices (not averaged face normals).
    uv : ndarray (V, 2) float64 (or float32), or None
        Texture coordinates: ``u`` = arc length of the spine at the vertex's ring (in the
        units of the points), ``v`` = arc length around the profile / its perimeter.
    fold_over : ndarray (k,) int64
        Spine rows starting a segment where the surface folds over itself (empty when
        none); see :class:`FoldOverWarning`.
    point_data : dict of str to ndarray (V,) or (V, k)
        Per-vertex attributes: the ``point_data=`` of the sweep, each sample's (or curve's)
        value on every vertex of its ring (caps included).
    cell_data : dict of str to ndarray (F,) or (F, k)
        Per-face attributes; sweeps of a bundle put the curve of every face in
        ``"curve_id"`` (built when ``cell_data`` is first read: 4 bytes per face that a
        caller who never reads it does not pay for).
    sample_of, curve_of : ndarray (V,) int64 or None
        The spine row (as given: rows of all curves back to back) and the curve of every
        vertex of a sweep (None for meshes made otherwise). Computed when first read.
    skipped_curves : ndarray (k,) int64
        Curves of a bundle left out by ``on_short="skip"`` (empty when none).
    """

    vertices: npt.NDArray[np.float64] | npt.NDArray[np.float32]
    faces: Int64Array | npt.NDArray[np.int32]
    normals: Float64Array | None
    uv: Float64Array | None
    fold_over: Int64Array
    point_data: dict[str, npt.NDArray[Any]]
    skipped_curves: Int64Array
    # the lazily built layouts of a sweep's mesh
    _cell_data: dict[str, npt.NDArray[Any]]
    _curve_id_runs: tuple[np.ndarray, np.ndarray] | None
    _sample_of: Int64Array | None
    _curve_of: Int64Array | None
    _rings: Any  # (ring_sample, ring_curve, cols), a function returning it, or None
    _n_rows: int | None
    _n_curves: int | None

    def __init__(
        self,
        vertices: Array,
        faces: Array,
        normals: Array | None = None,
        uv: Array | None = None,
        fold_over: Array | None = None,
        *,
        point_data: PointData | None = None,
        cell_data: PointData | None = None,
        sample_of: Array | None = None,
        curve_of: Array | None = None,
        skipped_curves: Array | None = None,
    ) -> None:
        V = (vertices if isinstance(vertices, np.ndarray) and vertices.dtype == np.float32
             else as_float_array(vertices, "vertices"))
        if V.ndim != 2 or V.shape[1] != 3:
            raise ValueError(f"vertices: expected an array of shape (V, 3), got shape {V.shape}")
        _core.mesh_check_finite(np.ascontiguousarray(V), "vertices")
        n = len(V)
        F = _as_faces(faces, n)
        self.vertices, self.faces = V, F
        self.normals = _rows_or_none(normals, "normals", n, 3)
        self.uv = _rows_or_none(uv, "uv", n, 2)
        self.fold_over = _index_array(fold_over, "fold_over")
        self.point_data = _attributes(point_data, "point_data", n)
        self.cell_data = _attributes(cell_data, "cell_data", len(F))
        self._sample_of = _index_array(sample_of, "sample_of", n, none=True)
        self._curve_of = _index_array(curve_of, "curve_of", n, none=True)
        self._rings = self._n_rows = self._n_curves = None
        self.skipped_curves = _index_array(skipped_curves, "skipped_curves")

    @classmethod
    def _of_sweep(cls, vertices: np.ndarray, faces: np.ndarray, normals: np.ndarray | None,
                  uv: np.ndarray | None, fold_over: Array, rings: Any, rows: int,
                  curves: int) -> Mesh:
        """A sweep's mesh without the checks (the core built it); ``rings`` is the compact
        vertex layout ``(ring_sample (R,), ring_curve (R,), cols)``: stored ring ``r`` holds
        vertices ``r*cols .. (r+1)*cols`` of spine row ``ring_sample[r]``, curve
        ``ring_curve[r]`` (or a function returning it, called when first needed); the sweep
        had ``rows`` spine rows in ``curves`` curves."""
        mesh = cls.__new__(cls)
        mesh.vertices, mesh.faces, mesh.normals, mesh.uv = vertices, faces, normals, uv
        mesh.fold_over = np.asarray(fold_over, dtype=np.int64)
        mesh.point_data, mesh.cell_data = {}, {}
        mesh._sample_of = mesh._curve_of = None
        mesh._rings, mesh._n_rows, mesh._n_curves = rings, rows, curves
        mesh.skipped_curves = np.zeros(0, dtype=np.int64)
        return mesh

    @property
    def cell_data(self) -> dict[str, npt.NDArray[Any]]:
        """Per-face attributes (see the class docstring)."""
        runs = self.__dict__.get("_curve_id_runs")
        if runs is not None:
            self._curve_id_runs = None
            self._cell_data["curve_id"] = _repeat_in_blocks(*runs)
        return self._cell_data

    @cell_data.setter
    def cell_data(self, value: dict[str, npt.NDArray[Any]]) -> None:
        self._cell_data, self._curve_id_runs = value, None

    def _lazy_curve_id(self, curve_ids: np.ndarray, faces_per_curve: np.ndarray) -> None:
        """``cell_data["curve_id"]``: ``curve_ids[c]`` on the next ``faces_per_curve[c]``
        faces, built when ``cell_data`` is first read."""
        self._curve_id_runs = (curve_ids, faces_per_curve)

    def __setstate__(self, state: dict[str, Any]) -> None:
        if "cell_data" in state:  # pickled before cell_data was built on first read
            state["_cell_data"] = state.pop("cell_data")
        self.__dict__.update(state)

    def _ring_arrays(self) -> tuple[np.ndarray, np.ndarray, int]:
        """The sweep's ring layout ``(ring_sample, ring_curve, cols)``, built on first use."""
        if callable(self._rings):
            self._rings = self._rings()
        rings: tuple[np.ndarray, np.ndarray, int] = self._rings
        return rings

    @property
    def sample_of(self) -> Int64Array | None:
        """The spine row of every vertex, ``(V,)`` int64 (None when not from a sweep)."""
        if self._sample_of is None and self._rings is not None:
            rings = self._ring_arrays()
            self._sample_of = np.repeat(rings[0], rings[2])
        out: Int64Array | None = self._sample_of
        return out

    @sample_of.setter
    def sample_of(self, value: Int64Array | None) -> None:
        self._sample_of = _index_array(value, "sample_of", len(self.vertices), none=True)

    @property
    def curve_of(self) -> Int64Array | None:
        """The curve of every vertex, ``(V,)`` int64 (None when not from a sweep)."""
        if self._curve_of is None and self._rings is not None:
            rings = self._ring_arrays()
            self._curve_of = np.repeat(rings[1], rings[2])
        out: Int64Array | None = self._curve_of
        return out

    @curve_of.setter
    def curve_of(self, value: Int64Array | None) -> None:
        self._curve_of = _index_array(value, "curve_of", len(self.vertices), none=True)

    def __repr__(self) -> str:
        return f"spinal.Mesh({len(self.vertices)} vertices, {len(self.faces)} faces)"

    @property
    def volume(self) -> float:
        """Signed enclosed volume, ``Σ (a · (b × c)) / 6`` over the faces (divergence
        theorem); positive for a closed, outward-facing mesh. Summed about the mean vertex,
        so a small mesh far from the origin keeps its digits (compensated sums, in parallel,
        linear in the faces)."""
        return _core.mesh_measure(*self._arrays(), "volume")

    @property
    def area(self) -> float:
        """Total surface area (compensated sums, in parallel, linear in the faces)."""
        return _core.mesh_measure(*self._arrays(), "area")

    def edge_stats(self) -> dict[str, int]:
        """Counts of the undirected edges (by vertex index): ``edges``, ``boundary`` (in one
        face), ``non_manifold`` (in more than two), ``inconsistent`` (in two faces that
        traverse it the same way) and ``degenerate`` (face corners joining a vertex to
        itself). A counting sort of the face slots on their smaller vertex: linear time,
        ``O(F)`` integers of memory, in parallel."""
        V, F = self._arrays()
        keys = ("edges", "boundary", "non_manifold", "inconsistent", "degenerate")
        return dict(zip(keys, _core.mesh_edges(F, len(V))))

    def self_intersections(self, limit: int = 10_000_000) -> npt.NDArray[np.int64]:
        """The pairs of faces that intersect other than along the vertices and edges they
        share: ``(K, 2)`` int64 face indices ``i < j``, sorted (empty for an embedded mesh).

        Exact: orientation tests with Shewchuk's adaptive-precision predicates, so touching
        and coplanar overlaps are decided without tolerance. Two faces sharing an edge count
        when they lie in one plane folded onto each other; sharing a vertex, when they meet
        anywhere else; duplicate faces count; faces of zero area are left out (see
        ``edge_stats``). Candidates come from a bounding-volume hierarchy of the faces
        (``O(F log F)`` for evenly sized faces), in parallel, the same pairs on any thread
        count; Ctrl-C stops it.

        Parameters
        ----------
        limit : int
            Stop after this many pairs (a ``RuntimeWarning`` says so).
        """
        from ._validate import as_int

        limit = as_int(limit, "limit", 0, 1 << 40)
        pairs, truncated = _core.mesh_self_intersections(*self._arrays(), limit)
        if truncated:
            import warnings

            warnings.warn(RuntimeWarning(
                f"self_intersections: stopped at limit={limit:,} pairs; more faces cross"),
                stacklevel=2)
        return pairs

    @property
    def is_watertight(self) -> bool:
        """Every edge is shared by exactly two faces that traverse it in opposite directions
        (closed, consistently oriented, by vertex index)."""
        e = self.edge_stats()
        return e["boundary"] == e["non_manifold"] == e["inconsistent"] == e["degenerate"] == 0

    @property
    def is_closed(self) -> bool:
        """Every edge is shared by exactly two faces, whatever their orientation
        (``trimesh.Trimesh.is_watertight``)."""
        e = self.edge_stats()
        return e["boundary"] == e["non_manifold"] == e["degenerate"] == 0

    @property
    def is_winding_consistent(self) -> bool:
        """Every edge shared by two faces is traversed by them in opposite directions
        (``trimesh.Trimesh.is_winding_consistent``)."""
        return self.edge_stats()["inconsistent"] == 0

    def _arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """Vertices and faces as the core reads them (C-contiguous, float32/64, int32/64)."""
        V, F = self.vertices, self.faces
        if V.dtype not in (np.float32, np.float64):
            V = np.asarray(V, dtype=np.float64)
        if F.dtype not in (np.int32, np.int64):
            F = np.asarray(F, dtype=np.int64)
        return np.ascontiguousarray(V), np.ascontiguousarray(F).reshape(-1, 3)

    @staticmethod
    def concatenate(meshes: Sequence[Mesh]) -> Mesh:
        """One mesh of all ``meshes`` (a sequence of :class:`Mesh`), for chunked pipelines:
        vertices stacked, faces offset by the vertices before them. ``normals``/``uv`` are kept
        when every mesh has them; ``point_data``/``cell_data`` keys present in every mesh are
        kept. ``sample_of``, ``fold_over`` (spine rows) are offset by the rows of the meshes
        before (their largest row + 1, or the rows the sweep was given), ``curve_of``,
        ``skipped_curves`` and ``cell_data["curve_id"]`` by their curves, so chunks of a
        bundle swept one by one give the mesh of the whole bundle."""
        if isinstance(meshes, Mesh):
            raise TypeError("meshes: expected a sequence of spinal.Mesh, got one Mesh (pass "
                            "a list: Mesh.concatenate([a, b, ...]))")
        try:
            meshes = list(meshes)
        except TypeError:
            raise TypeError(f"meshes: expected a sequence of spinal.Mesh, got "
                            f"{type(meshes).__name__}") from None
        if not meshes or not all(isinstance(m, Mesh) for m in meshes):
            raise TypeError("meshes: expected a non-empty sequence of spinal.Mesh")
        V = np.concatenate([m.vertices for m in meshes])
        nv = np.cumsum([0] + [len(m.vertices) for m in meshes])
        big = nv[-1] > np.iinfo(np.int32).max
        ftype: type[np.signedinteger[Any]] = np.int64 if big or any(m.faces.dtype == np.int64 for m in meshes) else np.int32
        F = np.concatenate([m.faces.astype(ftype, copy=False) + ftype(o)
                            for m, o in zip(meshes, nv[:-1])])

        def joined(attr: str) -> np.ndarray | None:
            parts = [getattr(m, attr) for m in meshes]
            return None if any(p is None for p in parts) else np.concatenate(parts)

        rows = np.cumsum([0] + [_rows_of(m) for m in meshes])
        curves = np.cumsum([0] + [_curves_of(m) for m in meshes])

        def shifted(attr: str, shift: np.ndarray) -> np.ndarray | None:
            parts = [getattr(m, attr) for m in meshes]
            if any(p is None for p in parts):
                return None
            return np.concatenate([p + s for p, s in zip(parts, shift)])

        def common(attr: str, shift_curve: bool) -> dict[str, np.ndarray]:
            keys = [k for k in getattr(meshes[0], attr)
                    if all(k in getattr(m, attr) for m in meshes)]
            out: dict[str, np.ndarray] = {}
            for k in keys:
                parts = [getattr(m, attr)[k] for m in meshes]
                if shift_curve and k == "curve_id":
                    parts = [p + s for p, s in zip(parts, curves)]
                if len({np.shape(p)[1:] for p in parts}) > 1:
                    raise ValueError(f"meshes: {attr}[{k!r}] has rows of different shapes in "
                                     f"the meshes ({sorted({np.shape(p)[1:] for p in parts})})"
                                     f"; give every mesh the same columns under one name")
                out[k] = np.concatenate(parts)
            return out

        mesh = Mesh.__new__(Mesh)
        mesh.vertices, mesh.faces = V, F
        mesh.normals, mesh.uv = joined("normals"), joined("uv")
        mesh.fold_over = np.concatenate([m.fold_over + s for m, s in zip(meshes, rows)])
        mesh.point_data = common("point_data", False)
        mesh.cell_data = common("cell_data", True)
        mesh._sample_of, mesh._curve_of, mesh._rings = (
            shifted("sample_of", rows), shifted("curve_of", curves), None)
        mesh._n_rows, mesh._n_curves = int(rows[-1]), int(curves[-1])
        mesh.skipped_curves = np.concatenate(
            [m.skipped_curves + s for m, s in zip(meshes, curves)]).astype(np.int64)
        return mesh

    def to_trimesh(self) -> Any:
        """A ``trimesh.Trimesh`` with the same vertices, faces and normals (no merging or
        reordering; ``uv`` goes to a ``TextureVisuals`` when present, else a ``point_data``
        array ``"colors"`` (RGB(A), as in :meth:`save`) to the vertex colours; ``point_data``
        and ``cell_data`` to ``vertex_attributes`` and ``face_attributes``)."""
        import trimesh

        visual: Any = None
        if self.uv is not None:
            visual = trimesh.visual.TextureVisuals(uv=self.uv)
        elif "colors" in self.point_data:
            rgb, _ = _files.vertex_colors(self, "colors")
            visual = trimesh.visual.ColorVisuals(vertex_colors=rgb)
        return trimesh.Trimesh(
            vertices=self.vertices,
            faces=self.faces,
            vertex_normals=self.normals,
            visual=visual,
            process=False,
            vertex_attributes=dict(self.point_data),
            face_attributes=dict(self.cell_data),
        )

    def to_pyvista(self) -> Any:
        """A ``pyvista.PolyData`` with point data ``Normals`` (active normals), the texture
        coordinates ``uv`` and every array of ``point_data``; cell data from ``cell_data``."""
        import pyvista as pv

        cells = np.hstack([np.full((len(self.faces), 1), 3, dtype=np.int64), self.faces])
        poly = pv.PolyData(self.vertices, cells.ravel())
        if self.normals is not None:
            poly.point_data["Normals"] = self.normals
            poly.point_data.active_normals_name = "Normals"
        if self.uv is not None:
            poly.point_data["uv"] = self.uv
            poly.point_data.active_texture_coordinates_name = "uv"
        for k, v in self.point_data.items():
            poly.point_data[k] = v
        for k, v in self.cell_data.items():
            poly.cell_data[k] = v
        return poly

    def save(
        self, path: str | os.PathLike[str], *, colors: str | Array | None = None
    ) -> pathlib.Path:
        """Write the mesh to ``path``; no third-party package is needed. Returns the path.

        * ``.ply``: binary little-endian PLY: positions, normals ``nx ny nz`` and texture
          coordinates ``s t``, vertex colours ``red green blue (alpha)`` (uchar), then every
          other ``point_data`` array as vertex properties (``name``, or ``name_0 …
          name_{k-1}`` for ``(V, k)``), faces as int32 vertex lists followed by the
          ``cell_data`` arrays as face properties.
        * ``.vtp``: VTK XML PolyData (appended raw binary, 64-bit headers): points, triangles,
          point data ``Normals`` and ``uv`` (texture coordinates), the colours as the active
          ``UInt8`` scalars ``colors`` and ``point_data``; cell data from ``cell_data``. Read
          by VTK/pyvista and ParaView.
        * ``.obj``: Wavefront OBJ (``v``, ``vn``, ``vt`` and ``f v/vt/vn`` lines, 17
          significant digits; colours as ``v x y z r g b`` in [0, 1], the extension that
          MeshLab, Blender and trimesh read); other attributes are not written.
        * ``.stl``: binary STL (float32 corners and face normals; positions only).
        * ``.glb``: binary glTF 2.0 (float32 positions, normals, texture coordinates and
          the colours as ``COLOR_0``; uint32 indices), for Blender, three.js and viewers
          on the web; other attributes are not written.

        Parameters
        ----------
        path : str or os.PathLike
            The file; its suffix (``.ply``, ``.vtp``, ``.obj``, ``.stl``, ``.glb``) picks
            the format.
        colors : str or array_like (V, 3) or (V, 4), optional
            Vertex colours (RGB or RGBA): ``uint8`` in 0 … 255 or floats in [0, 1] (stored
            as ``round(255 x)``), or the name of a ``point_data`` array holding them. By
            default the ``point_data`` array ``"colors"`` is used when there is one. The
            colours replace that array in the file (its other arrays keep their names), so
            MeshLab, ParaView, Blender and trimesh show them.
        """
        return _files.write(self, path, colors)

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Mesh:
        """Read a triangle mesh: ``.ply``, ``.obj``, ``.stl``, ``.glb``/``.gltf`` and
        ``.off`` through trimesh, ``.vtp``/``.vtk`` through pyvista (polygons are
        triangulated). Normals, texture coordinates, vertex colours (as ``point_data
        ["colors"]``, uint8) and other per-vertex (and, from VTK, per-face) arrays come
        along where the file has them; vertices are not merged or reordered, so a mesh
        written by :meth:`save` comes back with the same rows.
        """
        return cls(**_files.read(path))

    def plot(
        self,
        screenshot: str | os.PathLike[str] | None = None,
        *,
        window_size: tuple[int, int] = (800, 600),
        **kwargs: Any,
    ) -> npt.NDArray[np.uint8] | None:
        """Render with pyvista.

        Off-screen (when there is no display, or when ``screenshot`` is given) the image is
        returned as an ``(h, w, 3)`` uint8 array and written to ``screenshot`` if given;
        otherwise an interactive window opens. Extra keyword arguments go to
        ``Plotter.add_mesh`` (default: smooth shading with sharp edges split, so caps and
        profile corners stay crisp).
        """
        import pyvista as pv

        off = screenshot is not None or pv.OFF_SCREEN or not _has_display()
        pl = pv.Plotter(off_screen=off, window_size=list(window_size))
        kwargs.setdefault("smooth_shading", True)
        kwargs.setdefault("split_sharp_edges", True)
        kwargs.setdefault("color", "#c9a227")
        pl.add_mesh(self.to_pyvista(), **kwargs)
        pl.camera_position = "iso"
        pl.reset_camera()
        if off:
            img = pl.screenshot(None if screenshot is None else os.fspath(screenshot),
                                return_img=True)
            pl.close()
            shot: npt.NDArray[np.uint8] = img
            return shot
        pl.show()
        return None



def _has_display() -> bool:
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


# elements per step of `_repeat_in_blocks`
REPEAT_BLOCK = 1 << 22


def _repeat_in_blocks(values: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """``np.repeat(values, counts)`` written in steps of at most ``REPEAT_BLOCK`` elements,
    so that Ctrl-C (acted on by Python between the steps) stops a large one promptly."""
    ends = np.cumsum(counts, dtype=np.int64)
    starts = ends - counts
    total = int(ends[-1]) if ends.size else 0
    out = np.empty(total, dtype=values.dtype)
    for a in range(0, total, REPEAT_BLOCK):
        b = min(a + REPEAT_BLOCK, total)
        # the values whose runs meet [a, b), their runs clipped to it
        i = int(np.searchsorted(ends, a, side="right"))
        j = int(np.searchsorted(starts, b, side="left"))
        out[a:b] = np.repeat(values[i:j], np.minimum(ends[i:j], b) - np.maximum(starts[i:j], a))
    return out
