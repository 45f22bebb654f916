r"""Fleshing with a spine surface: a shape bound to a grid surface or a triangle mesh keeps
its volume locally when the surface moves (Zhuo 2014 Ch. VI). See :class:`SurfaceBinding` and
:func:`flesh_surface`.
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING, Any, Literal, overload

import numpy as np

from . import _core
from ._flesh_roll import _unit_sized
from ._mesh import FoldOverWarning
from ._types import Array, Float64Array, Int64Array, SurfaceSolution
from ._validate import as_bool, as_choice, as_float_array

if TYPE_CHECKING:
    from ._mesh import Mesh


def _grid(x: object, name: str) -> np.ndarray:
    arr = as_float_array(x, name)
    if arr.ndim != 3 or arr.shape[2] != 3 or arr.shape[0] < 2 or arr.shape[1] < 2:
        raise ValueError(f"{name}: expected a grid of shape (nu, nv, 3), nu, nv ≥ 2, got "
                         f"{arr.shape}")
    return np.ascontiguousarray(arr)


def _is_mesh(x: object) -> bool:
    """A triangulated surface: ``(vertices, faces)`` with integer faces, or an object with
    ``vertices`` and ``faces`` (spinal.Mesh, trimesh.Trimesh)."""
    if isinstance(x, tuple) and len(x) == 2:
        return np.asarray(x[1]).dtype.kind in "iu"
    return hasattr(x, "vertices") and hasattr(x, "faces")


def _mesh(x: object, name: str) -> tuple[np.ndarray, np.ndarray]:
    """``(vertices (n, 3) float64, faces (F, 3) int64)`` of a triangulated surface; the core
    checks the values (finite, indices in range, no degenerate faces)."""
    given: Any = x
    vertices, faces = given if isinstance(given, tuple) else (given.vertices, given.faces)
    V = as_float_array(vertices, name)
    if V.ndim != 2 or V.shape[1] != 3:
        raise ValueError(f"{name}: expected vertices of shape (n, 3), got {V.shape}")
    F = np.asarray(faces)
    if F.dtype.kind not in "iu":
        raise TypeError(f"{name}: expected integer faces, got dtype {F.dtype}")
    if F.ndim != 2 or F.shape[1] != 3 or len(F) == 0:
        raise ValueError(f"{name}: expected faces of shape (F, 3), F ≥ 1, got {F.shape}")
    if F.dtype.kind == "u" and F.max() > np.iinfo(np.int64).max:
        raise ValueError(f"{name}: face index {F.max()} out of range ({len(V)} vertices)")
    return (np.ascontiguousarray(V, dtype=np.float64),
            np.ascontiguousarray(F, dtype=np.int64))


def _surface_frames(g: np.ndarray) -> np.ndarray:
    """``(nu, nv, 3, 3)`` frames at the grid samples, columns ``(e1, e2, N)``: ``N`` the unit
    ``S_u × S_v`` and ``e1`` the unit ``S_u`` projected on its normal plane, both by the
    central differences of the core (one-sided at the border), ``e2 = N × e1``."""
    g = _unit_sized(g)  # the cross products of differences leave float64's range far from 1
    nu, nv = g.shape[:2]
    iu = np.arange(nu)
    iv = np.arange(nv)
    i0, i1 = np.maximum(iu - 1, 0), np.minimum(iu + 1, nu - 1)
    j0, j1 = np.maximum(iv - 1, 0), np.minimum(iv + 1, nv - 1)
    du = g[i1] - g[i0]
    dv = g[:, j1] - g[:, j0]
    n = np.cross(du, dv)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    e1 = du - np.sum(du * n, axis=-1, keepdims=True) * n
    e1 /= np.linalg.norm(e1, axis=-1, keepdims=True)
    return np.stack([e1, np.cross(n, e1), n], axis=-1)


def _surface_directions(posed_frames: Array | None, posed_up: Array | None,
                        shape: tuple[int, ...]) -> tuple[str, np.ndarray] | None:
    """The ``(name, (rows, 3) directions)`` the core lays the offsets along, or ``None``;
    ``shape`` is the grid's ``(nu, nv)`` or the triangulated surface's ``(n,)``."""
    if posed_frames is None and posed_up is None:
        return None
    if posed_frames is not None and posed_up is not None:
        raise TypeError("posed_frames, posed_up: pass one of them, not both")
    shape = tuple(shape)
    dims = ", ".join(map(str, shape))
    like = "posed_surface's grid" if len(shape) == 2 else "posed_surface's vertices"
    where = "grid point" if len(shape) == 2 else "vertex"
    if posed_frames is not None:
        f = as_float_array(posed_frames, "posed_frames")
        if f.shape != (*shape, 3, 3):
            raise ValueError(f"posed_frames: expected shape ({dims}, 3, 3) like "
                             f"{like}, got {f.shape}")
        err = np.abs(np.swapaxes(f, -1, -2) @ f - np.eye(3)).max(axis=(-2, -1))
        bad = np.argwhere(~(err < 1e-6) | ~(np.linalg.det(f) > 0))
        if bad.size:
            at = ", ".join(map(str, bad[0]))
            at = f"({at})" if len(shape) == 2 else at
            raise ValueError(f"posed_frames: {where} {at} is not a rotation (expected "
                             f"orthonormal columns (S_u direction, in-surface perpendicular, "
                             f"normal) with det +1, like SurfaceBinding.rest_frames)")
        return "posed_frames", np.ascontiguousarray(f[..., 2].reshape(-1, 3))
    u = as_float_array(posed_up, "posed_up")
    if u.shape == (3,):
        u = np.broadcast_to(u, (*shape, 3))
    if u.shape != (*shape, 3):
        raise ValueError(f"posed_up: expected shape (3,) or ({dims}, 3) like {like}, got "
                         f"{u.shape}")
    return "posed_up", np.ascontiguousarray(u.reshape(-1, 3))


class SurfaceBinding:
    r"""A shape registered on a rest spine surface (Zhuo 2014 Ch. VI), to be posed many times.

    The surface is a grid of samples ``(nu, nv, 3)``, a bicubic Hermite patch in every cell
    (derivatives by central differences, C¹ across cells), with the unit normal interpolated
    the same way from the sample normals (central differences ``S_u × S_v``, so the normal's
    side follows the grid's orientation); the map is therefore continuous across cells. Every vertex is registered by its foot
    ``(u, v)`` and signed offset ``h`` along that normal (``P = S(u, v) + h N(u, v)``; the
    foot is found by Newton's method in the cells around the nearest sample; the smallest
    ``|h|`` wins). Vertices whose foot lies outside the grid are attached to the border with
    their offset carried rigidly (not volume preserving; reported as clamped).

    :meth:`deform` keeps every normal segment on the normal of the posed surface at the same
    ``(u, v)`` and corrects its length with the mean and Gaussian curvature and the area
    stretch (Eq. 38–43): ``A1 h1 + B1 h1²/2 + C1 h1³/3 = A0 h0 + B0 h0²/2 + C0 h0³/3`` where
    ``A + B h + C h² = det[S_u + hN_u, S_v + hN_v, N]`` is the model's exact volume element
    (``B = −2mA``, ``C = gA``), so the map's Jacobian determinant is 1. Where no fold-free
    root exists, ``h1`` is clamped to the largest fold-free offset ``1/k_max`` (§6.2).

    **Triangulated surfaces.** ``rest_surface`` may instead be a triangle mesh
    ``(surface_vertices, faces)`` (or a :class:`spinal.Mesh` / ``trimesh.Trimesh``), posed by
    moving its vertices (:meth:`deform` takes the posed vertex array, same faces). Every face
    is flat; the normal is the barycentric interpolation of the unit angle-weighted vertex
    normals, made unit (the normal side is the one the faces' winding gives). A vertex is
    registered by its face, barycentric coordinates and offset along that interpolated
    normal (``P = S + h N``; the face is searched around the closest point of the mesh,
    found with a bounding-volume hierarchy). The volume element of this model is
    ``A + B h + C h²`` exactly as above, with ``S_u, S_v`` the face's edges and
    ``N_u = (I − NNᵀ)(n_b − n_a)/|M|`` (``M`` the interpolated, not yet unit, normal): the
    faces are flat and all the curvature ``m = −B/(2A)``, ``g = C/A`` lies in the
    interpolated normals. :meth:`deform` solves the same equation with the face's own ``A, B,
    C`` at the foot, so the Jacobian determinant is 1 inside the normal prism of every face.
    ``A, B, C`` jump across edges (they are derivatives of a piecewise-linear surface), and
    so does the corrected offset: the map is continuous across faces only where the pose
    keeps them (the identity, or an affine map of a flat surface in its plane); elsewhere the
    jump is first order in the edge length, and a shape that crosses edges gains or loses
    thin slivers there, which shrink as the surface is refined. :attr:`rest_frames` and
    the ``posed_frames``/``posed_up`` of :meth:`deform` are per vertex. On a flat grid posed by an affine map of its plane (rigid motion, stretch,
    shear) the triangulated grid gives the grid model's result (both are exact there:
    ``h1 = h0 A0/A1``); on a bent grid the two models differ by their discretisation errors
    (the grid's bicubic cells against flat faces with interpolated normals), and the
    difference falls as the grid is refined (first order in the grid step).

    Parameters
    ----------
    vertices : array_like (V, 3)
    rest_surface : array_like (nu, nv, 3), nu, nv ≥ 2, or a triangle mesh
        ``(surface_vertices (n, 3), faces (F, 3))``, a :class:`spinal.Mesh` or a
        ``trimesh.Trimesh`` (faces in range, not degenerate, consistently oriented). A
        2-tuple whose second item has an integer dtype is read as ``(vertices, faces)``; give
        a grid as one array.
    """

    clamped: Int64Array
    _faces: np.ndarray | None  # the rest faces of a triangulated surface (None: a grid)
    _shape: tuple[int, ...] | None  # the grid's (nu, nv) (None: triangles)

    def __init__(
        self, vertices: Array, rest_surface: Array | Mesh | tuple[Array, Array]
    ) -> None:
        v = as_float_array(vertices, "vertices")
        if v.ndim != 2 or v.shape[1] != 3:
            raise ValueError(f"vertices: expected shape (V, 3), got {v.shape}")
        if _is_mesh(rest_surface):
            sv, faces = _mesh(rest_surface, "rest_surface")
            self._faces = faces
            self._shape = None
            self._rest_frames = _core.flesh_trisurface_frames(sv, faces)
            self._cell, self._coords, self._exp = _core.flesh_trisurface_bind(
                sv, faces, np.ascontiguousarray(v, dtype=np.float64))
            self._nverts = len(sv)
            self.clamped = np.zeros(0, dtype=np.int64)
            return
        self._faces = None
        g = _grid(rest_surface, "rest_surface")
        self._shape = g.shape[:2]
        self._rest_frames = _surface_frames(g)
        self._cell, self._coords, self._exp = _core.flesh_surface_bind(
            g.reshape(-1, 3), g.shape[0], g.shape[1], np.ascontiguousarray(v, dtype=np.float64)
        )
        self.clamped = np.zeros(0, dtype=np.int64)

    def __len__(self) -> int:
        return len(self._cell)

    @property
    def face(self) -> Int64Array:
        """``(V,)`` int64: the face of each foot (triangulated surfaces only)."""
        self._only("face", triangles=True)
        return self._cell.copy()

    @property
    def barycentric(self) -> Float64Array:
        """``(V, 3)`` barycentric coordinates of the feet on their faces (triangulated
        surfaces only)."""
        self._only("barycentric", triangles=True)
        u, v = self._coords[:, 0], self._coords[:, 1]
        out: Float64Array = np.c_[1 - u - v, u, v]
        return out

    def _only(self, name: str, triangles: bool) -> None:
        if (self._faces is not None) != triangles:
            kind = "a triangulated" if triangles else "a grid"
            raise TypeError(f"{name}: only for {kind} rest_surface")

    @property
    def uv(self) -> Float64Array:
        """``(V, 2)`` grid coordinates ``(i + u, j + v)`` of the feet (grids only)."""
        self._only("uv", triangles=False)
        assert self._shape is not None  # (a grid)
        i, j = np.divmod(self._cell, self._shape[1])
        out: Float64Array = np.c_[i + self._coords[:, 0], j + self._coords[:, 1]]
        return out

    @property
    def offset(self) -> Float64Array:
        """``(V,)`` signed offsets ``h`` along the rest normal."""
        return self._coords[:, 2].copy()

    @property
    def rest_frames(self) -> Float64Array:
        """``(nu, nv, 3, 3)`` frames of the rest surface at its samples, columns ``(e1, e2,
        N)``: ``e1`` the direction of ``S_u``, ``e2 = N × e1`` in the surface, ``N`` the
        normal (all by the central differences the binding uses). ``R @ rest_frames`` are
        the ``posed_frames`` of the surface moved by ``x ↦ Rx + c``.

        For a triangulated rest surface: ``(n, 3, 3)`` frames at its vertices, ``N`` the
        unit angle-weighted vertex normal the binding uses, ``e1`` the first edge
        ``S_b − S_a`` (the face's ``S_u``) of the lowest-numbered face ``(a, b, c)`` around
        the vertex, projected on the plane normal to ``N`` and made unit, ``e2 = N × e1``
        (the identity at vertices no face uses). On a grid triangulated with the faces
        ``(a, a + (1, 0), a + (1, 1))`` listed before ``(a, a + (1, 1), a + (0, 1))`` these
        are the grid's frames, except ``e1, e2`` at the corner sample ``(0, nv − 1)``, which
        only the second kind of face uses."""
        return self._rest_frames.copy()

    @overload
    def deform(
        self,
        posed_surface: Array,
        *,
        solution: SurfaceSolution = "offset",
        strict: bool = False,
        return_clamped: Literal[False] = False,
        posed_frames: Array | None = None,
        posed_up: Array | None = None,
    ) -> Float64Array: ...
    @overload
    def deform(
        self,
        posed_surface: Array,
        *,
        solution: SurfaceSolution = "offset",
        strict: bool = False,
        return_clamped: Literal[True],
        posed_frames: Array | None = None,
        posed_up: Array | None = None,
    ) -> tuple[Float64Array, Int64Array]: ...
    @overload
    def deform(
        self,
        posed_surface: Array,
        *,
        solution: SurfaceSolution = "offset",
        strict: bool = False,
        return_clamped: bool = False,
        posed_frames: Array | None = None,
        posed_up: Array | None = None,
    ) -> Float64Array | tuple[Float64Array, Int64Array]: ...
    def deform(
        self,
        posed_surface: Array,
        *,
        solution: SurfaceSolution = "offset",
        strict: bool = False,
        return_clamped: bool = False,
        posed_frames: Array | None = None,
        posed_up: Array | None = None,
    ) -> Float64Array | tuple[Float64Array, Int64Array]:
        """The shape on ``posed_surface`` (same grid shape; for a triangulated rest surface
        the posed vertex array ``(n, 3)``, or a mesh with the same faces): ``(V, 3)``.

        ``solution="offset"`` (default) corrects the offset (volume preserving);
        ``"none"`` keeps ``h1 = h0`` (the uncorrected map). Clamped vertices (no fold-free
        offset, or foot outside the grid) are reported as in :meth:`SpineBinding.deform`.

        By default every normal segment is laid along the posed surface's normal. It can
        instead be laid along directions the caller gives at the posed samples, interpolated
        over the cells exactly as the sample normals are (bicubic Hermite with
        central-difference derivatives, made unit: C¹): ``P = S(u, v) + h1 D(u, v)``. The
        volume element ``det[S_u + h D_u, S_v + h D_v, D]`` holds for any unit field ``D``
        across the surface, so ``"offset"`` still keeps the volume (Jacobian determinant 1);
        with a constant ``D`` it is ``(S_u × S_v)·D`` and ``h1 = h0 A0/A1``.

        On a triangulated surface the directions are given at the posed vertices and
        interpolated over the faces as the vertex normals are (barycentric, made unit); the
        face's volume element ``det[S_u + h D_u, S_v + h D_v, D]`` (``D_u = (I − DDᵀ)(d_b −
        d_a)/|M|``) is solved for, so ``"offset"`` keeps the Jacobian determinant 1 inside
        every face's prism.

        Parameters
        ----------
        posed_frames : array_like (nu, nv, 3, 3) or, triangulated, (n, 3, 3), optional
            Frames at the posed samples (vertices), columns ``(S_u direction, in-surface
            perpendicular, normal)`` like :attr:`rest_frames`; proper rotations (so the
            first two columns are orthogonal to the third). Only the normal column is used:
            it carries the normal segment there. ``R @ binding.rest_frames`` with the
            surface moved by ``x ↦ Rx + c`` moves the shape rigidly; a rig can tilt the
            segments.
        posed_up : array_like (3,), (nu, nv, 3) or, triangulated, (n, 3), optional
            Instead of ``posed_frames``: directions (one for all samples, or one per sample;
            made unit) along which the offset is laid instead of the normal, e.g. a constant
            "up" keeps a skin's thickness vertical on a sheared surface.

        Both must lie on the normal's side of the surface and not in it (refused where the
        cosine with the sample's or vertex's normal is 1e-3 or less, or where the
        interpolated direction reaches the surface's plane inside a cell; on a
        triangulated surface, where a face's corner direction is not on the face's side).
        """
        solution = as_choice(solution, "solution", ("offset", "none"))
        strict = as_bool(strict, "strict")
        return_clamped = as_bool(return_clamped, "return_clamped")
        if self._faces is not None:
            pv = self._posed_vertices(posed_surface)
            dirs = _surface_directions(posed_frames, posed_up, (self._nverts,))
            out, flags = _core.flesh_trisurface_deform(
                pv, self._faces, self._cell, self._coords,
                {"rest_exp": self._exp, "corrected": solution == "offset", "directions": dirs})
            res: Float64Array | tuple[Float64Array, Int64Array] = self._report(
                out, flags, strict, return_clamped)
            return res
        g = _grid(posed_surface, "posed_surface")
        if g.shape[:2] != self._shape:
            raise ValueError(f"posed_surface: expected the rest grid's shape "
                             f"{self._shape}, got {g.shape[:2]}")
        dirs = _surface_directions(posed_frames, posed_up, self._shape)
        out, flags = _core.flesh_surface_deform(g.reshape(-1, 3), g.shape[0], g.shape[1],
                                                self._cell, self._coords,
                                                {"rest_exp": self._exp,
                                                 "corrected": solution == "offset",
                                                 "directions": dirs})
        return self._report(out, flags, strict, return_clamped)

    def _posed_vertices(self, posed_surface: object) -> np.ndarray:
        """The posed vertices of a triangulated binding (an array, or a mesh whose faces
        are the rest faces)."""
        if _is_mesh(posed_surface):
            pv, faces = _mesh(posed_surface, "posed_surface")
            if self._faces is None or not np.array_equal(faces, self._faces):
                raise ValueError("posed_surface: its faces differ from rest_surface's")
        else:
            pv = as_float_array(posed_surface, "posed_surface")
        if pv.shape != (self._nverts, 3):
            raise ValueError(f"posed_surface: expected the rest surface's {self._nverts} "
                             f"vertices, shape ({self._nverts}, 3), got {pv.shape}")
        return np.ascontiguousarray(pv, dtype=np.float64)

    def _report(self, out: Float64Array, flags: np.ndarray, strict: bool, return_clamped: bool
                ) -> Float64Array | tuple[Float64Array, Int64Array]:
        clamped = np.flatnonzero(flags).astype(np.int64)
        self.clamped = clamped
        if clamped.size:
            msg = (f"posed_surface: {clamped.size} vertices have no fold-free offset or lie "
                   f"outside the surface and were clamped, e.g. vertex {clamped[0]}")
            if strict:
                raise ValueError(msg)
            warnings.warn(FoldOverWarning(msg, clamped), stacklevel=3)
        return (out, clamped) if return_clamped else out


@overload
def flesh_surface(
    vertices: Array,
    rest_surface: Array | Mesh | tuple[Array, Array],
    posed_surface: Array,
    *,
    solution: SurfaceSolution = "offset",
    strict: bool = False,
    return_clamped: Literal[False] = False,
    posed_frames: Array | None = None,
    posed_up: Array | None = None,
) -> Float64Array: ...
@overload
def flesh_surface(
    vertices: Array,
    rest_surface: Array | Mesh | tuple[Array, Array],
    posed_surface: Array,
    *,
    solution: SurfaceSolution = "offset",
    strict: bool = False,
    return_clamped: Literal[True],
    posed_frames: Array | None = None,
    posed_up: Array | None = None,
) -> tuple[Float64Array, Int64Array]: ...
@overload
def flesh_surface(
    vertices: Array,
    rest_surface: Array | Mesh | tuple[Array, Array],
    posed_surface: Array,
    *,
    solution: SurfaceSolution = "offset",
    strict: bool = False,
    return_clamped: bool = False,
    posed_frames: Array | None = None,
    posed_up: Array | None = None,
) -> Float64Array | tuple[Float64Array, Int64Array]: ...
def flesh_surface(
    vertices: Array,
    rest_surface: Array | Mesh | tuple[Array, Array],
    posed_surface: Array,
    *,
    solution: SurfaceSolution = "offset",
    strict: bool = False,
    return_clamped: bool = False,
    posed_frames: Array | None = None,
    posed_up: Array | None = None,
) -> Float64Array | tuple[Float64Array, Int64Array]:
    """Bend a shape with a spine surface and keep its volume locally (Zhuo 2014 Ch. VI).

    One-shot form of ``SurfaceBinding(vertices, rest_surface).deform(posed_surface, ...)``
    (``posed_frames``/``posed_up``: the directions the offsets are laid along).
    """
    try:
        binding = SurfaceBinding(vertices, rest_surface)
    except MemoryError as e:
        raise MemoryError(f"flesh_surface: {e}") from None
    return binding.deform(
        posed_surface, solution=solution, strict=strict, return_clamped=return_clamped,
        posed_frames=posed_frames, posed_up=posed_up)
