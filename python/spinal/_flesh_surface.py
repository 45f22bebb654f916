r"""Fleshing with a spine surface: a shape bound to a grid surface keeps its volume locally
when the surface moves (Zhuo 2014 Ch. VI). See :class:`SurfaceBinding` and
:func:`flesh_surface`.
"""

from __future__ import annotations

import warnings

import numpy as np

from . import _core
from ._flesh import _unit_sized
from ._mesh import FoldOverWarning
from ._validate import as_bool, as_choice, as_float_array


def _grid(x, name: str) -> np.ndarray:
    arr = as_float_array(x, name)
    if arr.ndim != 3 or arr.shape[2] != 3 or arr.shape[0] < 2 or arr.shape[1] < 2:
        raise ValueError(f"{name}: expected a grid of shape (nu, nv, 3), nu, nv ≥ 2, got "
                         f"{arr.shape}")
    return np.ascontiguousarray(arr)


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


def _surface_directions(posed_frames, posed_up, shape):
    """The ``(name, (nu·nv, 3) directions)`` the core lays the offsets along, or ``None``."""
    if posed_frames is None and posed_up is None:
        return None
    if posed_frames is not None and posed_up is not None:
        raise TypeError("posed_frames, posed_up: pass one of them, not both")
    nu, nv = shape
    if posed_frames is not None:
        f = as_float_array(posed_frames, "posed_frames")
        if f.shape != (nu, nv, 3, 3):
            raise ValueError(f"posed_frames: expected shape ({nu}, {nv}, 3, 3) like "
                             f"posed_surface's grid, got {f.shape}")
        err = np.abs(np.swapaxes(f, -1, -2) @ f - np.eye(3)).max(axis=(-2, -1))
        bad = np.argwhere(~(err < 1e-6) | ~(np.linalg.det(f) > 0))
        if bad.size:
            i, j = bad[0]
            raise ValueError(f"posed_frames: grid point ({i}, {j}) is not a rotation (expected "
                             f"orthonormal columns (S_u direction, in-surface perpendicular, "
                             f"normal) with det +1, like SurfaceBinding.rest_frames)")
        return "posed_frames", np.ascontiguousarray(f[..., 2].reshape(-1, 3))
    u = as_float_array(posed_up, "posed_up")
    if u.shape == (3,):
        u = np.broadcast_to(u, (nu, nv, 3))
    if u.shape != (nu, nv, 3):
        raise ValueError(f"posed_up: expected shape (3,) or ({nu}, {nv}, 3) like "
                         f"posed_surface's grid, got {u.shape}")
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

    Parameters
    ----------
    vertices : array_like (V, 3)
    rest_surface : array_like (nu, nv, 3), nu, nv ≥ 2
    """

    def __init__(self, vertices, rest_surface):
        g = _grid(rest_surface, "rest_surface")
        v = as_float_array(vertices, "vertices")
        if v.ndim != 2 or v.shape[1] != 3:
            raise ValueError(f"vertices: expected shape (V, 3), got {v.shape}")
        self._shape = g.shape[:2]
        self._rest_frames = _surface_frames(g)
        self._cell, self._coords, self._exp = _core.flesh_surface_bind(
            g.reshape(-1, 3), g.shape[0], g.shape[1], np.ascontiguousarray(v, dtype=np.float64)
        )
        self.clamped = np.zeros(0, dtype=np.int64)

    def __len__(self) -> int:
        return len(self._cell)

    @property
    def uv(self) -> np.ndarray:
        """``(V, 2)`` grid coordinates ``(i + u, j + v)`` of the feet."""
        i, j = np.divmod(self._cell, self._shape[1])
        return np.c_[i + self._coords[:, 0], j + self._coords[:, 1]]

    @property
    def offset(self) -> np.ndarray:
        """``(V,)`` signed offsets ``h`` along the rest normal."""
        return self._coords[:, 2].copy()

    @property
    def rest_frames(self) -> np.ndarray:
        """``(nu, nv, 3, 3)`` frames of the rest surface at its samples, columns ``(e1, e2,
        N)``: ``e1`` the direction of ``S_u``, ``e2 = N × e1`` in the surface, ``N`` the
        normal (all by the central differences the binding uses). ``R @ rest_frames`` are
        the ``posed_frames`` of the surface moved by ``x ↦ Rx + c``."""
        return self._rest_frames.copy()

    def deform(self, posed_surface, *, solution: str = "offset", strict: bool = False,
               return_clamped: bool = False, posed_frames=None, posed_up=None):
        """The shape on ``posed_surface`` (same grid shape): ``(V, 3)``.

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

        Parameters
        ----------
        posed_frames : array_like (nu, nv, 3, 3), optional
            Frames at the posed samples, columns ``(S_u direction, in-surface perpendicular,
            normal)`` like :attr:`rest_frames`; proper rotations (so the first two columns
            are orthogonal to the third). Only the normal column is used: it carries the
            normal segment there. ``R @ binding.rest_frames`` with the surface moved by
            ``x ↦ Rx + c`` moves the shape rigidly; a rig can tilt the segments.
        posed_up : array_like (3,) or (nu, nv, 3), optional
            Instead of ``posed_frames``: directions (one for all samples, or one per sample;
            made unit) along which the offset is laid instead of the normal, e.g. a constant
            "up" keeps a skin's thickness vertical on a sheared surface.

        Both must lie on the normal's side of the surface and not in it (refused where the
        cosine with the sample normal is 1e-3 or less, or where the interpolated direction
        reaches the surface's plane inside a cell).
        """
        solution = as_choice(solution, "solution", ("offset", "none"))
        strict = as_bool(strict, "strict")
        return_clamped = as_bool(return_clamped, "return_clamped")
        g = _grid(posed_surface, "posed_surface")
        if g.shape[:2] != self._shape:
            raise ValueError(f"posed_surface: expected the rest grid's shape "
                             f"{self._shape}, got {g.shape[:2]}")
        dirs = _surface_directions(posed_frames, posed_up, self._shape)
        out, flags = _core.flesh_surface_deform(g.reshape(-1, 3), g.shape[0], g.shape[1],
                                                self._cell, self._coords, self._exp,
                                                solution == "offset", dirs)
        clamped = np.flatnonzero(flags).astype(np.int64)
        self.clamped = clamped
        if clamped.size:
            msg = (f"posed_surface: {clamped.size} vertices have no fold-free offset or lie "
                   f"outside the surface and were clamped, e.g. vertex {clamped[0]}")
            if strict:
                raise ValueError(msg)
            warnings.warn(FoldOverWarning(msg, clamped), stacklevel=2)
        return (out, clamped) if return_clamped else out


def flesh_surface(vertices, rest_surface, posed_surface, *, solution: str = "offset",
                  strict: bool = False, return_clamped: bool = False, posed_frames=None,
                  posed_up=None):
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
