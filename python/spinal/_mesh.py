"""The triangle mesh returned by the sweeps, with conversions to trimesh and pyvista."""

from __future__ import annotations

import os
import pathlib
from typing import Any

import numpy as np

from . import _core
from ._validate import as_float_array

__all__ = ["FoldOverWarning", "Mesh", "mesh_arrays"]


class FoldOverWarning(UserWarning):
    """The swept profile reaches past the spine's centre of curvature, so the surface folds
    over itself there. ``indices`` holds the spine rows that start the folded segments."""

    def __init__(self, message: str, indices: np.ndarray):
        super().__init__(message)
        self.indices = indices

    def __reduce__(self):
        # the default (cls, args, state) would call cls(message) without indices; pickling
        # matters for process pools, which send exceptions (and recorded warnings) back
        message = self.args[0] if self.args else ""
        return type(self), (message, self.indices), self.__dict__


def signed_volume(V: np.ndarray, F: np.ndarray) -> float:
    """Signed volume ``Σ (a · (b × c)) / 6`` of the triangles ``F`` over vertices ``V``
    (divergence theorem; positive for a closed, outward-facing mesh), summed about the mean
    vertex so that a small mesh far from the origin keeps its digits."""
    return _core.mesh_volume(np.ascontiguousarray(V, dtype=np.float64),
                             np.ascontiguousarray(F, dtype=np.int64).reshape(-1, 3))


def mesh_arrays(mesh):
    """``(vertices (V, 3) float64, faces (F, 3) int64)`` of a spinal.Mesh, a trimesh.Trimesh or a
    ``(vertices, faces)`` pair, named ``mesh`` in errors."""
    if isinstance(mesh, tuple) and len(mesh) == 2:
        V, F = mesh
    elif hasattr(mesh, "vertices") and hasattr(mesh, "faces"):
        V, F = mesh.vertices, mesh.faces
    else:
        raise TypeError("mesh: expected a spinal.Mesh, a trimesh.Trimesh or (vertices, faces)")
    V = np.ascontiguousarray(as_float_array(V, "mesh"), dtype=np.float64)
    F = np.asarray(F)
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


class Mesh:
    """A triangle mesh: what :func:`spinal.sweep` and :func:`spinal.tube` return.

    Attributes
    ----------
    vertices : ndarray (V, 3) float64
    faces : ndarray (F, 3) int64
        Vertex indices, counter-clockwise seen from outside (the right-hand normal points
        outwards on closed and capped sweeps).
    normals : ndarray (V, 3) float64
        Unit normals of the smooth swept surface at the vertices (not averaged face normals).
    uv : ndarray (V, 2) float64
        Texture coordinates: ``u`` = arc length of the spine at the vertex's ring (in the
        units of the points), ``v`` = arc length around the profile / its perimeter.
    fold_over : ndarray (k,) int64
        Spine rows starting a segment where the surface folds over itself (empty when
        none); see :class:`FoldOverWarning`.
    """

    def __init__(self, vertices, faces, normals=None, uv=None, fold_over=None):
        self.vertices = np.asarray(vertices, dtype=np.float64)
        self.faces = np.asarray(faces, dtype=np.int64)
        self.normals = None if normals is None else np.asarray(normals, dtype=np.float64)
        self.uv = None if uv is None else np.asarray(uv, dtype=np.float64)
        self.fold_over = (
            np.zeros(0, dtype=np.int64) if fold_over is None else np.asarray(fold_over, np.int64)
        )

    def __repr__(self) -> str:
        return f"spinal.Mesh({len(self.vertices)} vertices, {len(self.faces)} faces)"

    @property
    def volume(self) -> float:
        """Signed enclosed volume, ``Σ (a · (b × c)) / 6`` over the faces (divergence
        theorem); positive for a closed, outward-facing mesh. Summed about the mean vertex,
        so a small mesh far from the origin keeps its digits."""
        return signed_volume(self.vertices, self.faces)

    @property
    def area(self) -> float:
        """Total surface area."""
        a, b, c = (self.vertices[self.faces[:, k]] for k in range(3))
        return float(0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum())

    @property
    def is_watertight(self) -> bool:
        """Every edge is shared by exactly two faces that traverse it in opposite directions
        (closed, consistently oriented, by vertex index)."""
        f = self.faces
        e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
        key = e[:, 0] * (len(self.vertices) + 1) + e[:, 1]
        rev = e[:, 1] * (len(self.vertices) + 1) + e[:, 0]
        if np.unique(key).size != key.size:  # a directed edge used twice
            return False
        return bool(np.isin(rev, key).all())

    def to_trimesh(self):
        """A ``trimesh.Trimesh`` with the same vertices, faces and normals (no merging or
        reordering; ``uv`` goes to a ``TextureVisuals`` when present)."""
        import trimesh

        visual = None
        if self.uv is not None:
            visual = trimesh.visual.TextureVisuals(uv=self.uv)
        return trimesh.Trimesh(
            vertices=self.vertices,
            faces=self.faces,
            vertex_normals=self.normals,
            visual=visual,
            process=False,
        )

    def to_pyvista(self):
        """A ``pyvista.PolyData`` with point data ``Normals`` (active normals) and the
        texture coordinates ``uv``."""
        import pyvista as pv

        cells = np.hstack([np.full((len(self.faces), 1), 3, dtype=np.int64), self.faces])
        poly = pv.PolyData(self.vertices, cells.ravel())
        if self.normals is not None:
            poly.point_data["Normals"] = self.normals
            poly.point_data.active_normals_name = "Normals"
        if self.uv is not None:
            poly.point_data["uv"] = self.uv
            poly.point_data.active_texture_coordinates_name = "uv"
        return poly

    def save(self, path: str | os.PathLike) -> pathlib.Path:
        """Write the mesh to ``path``: binary little-endian PLY (``.ply``: positions, normals
        ``nx ny nz`` and texture coordinates ``s t`` as doubles, faces as int32 vertex lists)
        or Wavefront OBJ (``.obj``: ``v``, ``vn``, ``vt`` and ``f v/vt/vn`` lines, 17
        significant digits). No third-party package is needed. Returns the path."""
        path = pathlib.Path(path)
        suffix = path.suffix.lower()
        if suffix not in (".ply", ".obj"):
            raise ValueError(f"path: unknown format {suffix!r}; use .ply or .obj")
        if len(self.vertices) >= 2**31:
            raise ValueError("path: PLY/OBJ indices here are 32-bit; the mesh is too large")
        cols = [self.vertices]
        names = ["x", "y", "z"]
        if self.normals is not None:
            cols.append(self.normals)
            names += ["nx", "ny", "nz"]
        if self.uv is not None:
            cols.append(self.uv)
            names += ["s", "t"]
        if suffix == ".ply":
            vert = np.ascontiguousarray(np.hstack(cols), dtype="<f8")
            face = np.empty(len(self.faces), dtype=[("n", "u1"), ("v", "<i4", (3,))])
            face["n"] = 3
            face["v"] = self.faces
            header = ["ply", "format binary_little_endian 1.0", f"element vertex {len(vert)}"]
            header += [f"property double {n}" for n in names]
            header += [f"element face {len(face)}", "property list uchar int vertex_indices",
                       "end_header"]
            with open(path, "wb") as f:
                f.write(("\n".join(header) + "\n").encode("ascii"))
                f.write(vert.tobytes())
                f.write(face.tobytes())
            return path
        with open(path, "w") as f:
            f.write("# spinal mesh\n")
            np.savetxt(f, self.vertices, fmt="v %.17g %.17g %.17g")
            if self.normals is not None:
                np.savetxt(f, self.normals, fmt="vn %.17g %.17g %.17g")
            if self.uv is not None:
                np.savetxt(f, self.uv, fmt="vt %.17g %.17g")
            k = self.faces + 1
            if self.normals is not None and self.uv is not None:
                fmt, data = "f %d/%d/%d %d/%d/%d %d/%d/%d", np.repeat(k, 3, axis=1)
            elif self.normals is not None:
                fmt, data = "f %d//%d %d//%d %d//%d", np.repeat(k, 2, axis=1)
            elif self.uv is not None:
                fmt, data = "f %d/%d %d/%d %d/%d", np.repeat(k, 2, axis=1)
            else:
                fmt, data = "f %d %d %d", k
            np.savetxt(f, data, fmt=fmt)
        return path

    def plot(self, screenshot: str | os.PathLike | None = None, *, window_size=(800, 600),
             **kwargs: Any):
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
            return img
        pl.show()
        return None


def _has_display() -> bool:
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
