"""``spinal.deform``: advect a triangle mesh and refine its stretched edges from the rest mesh.

Refinement (thesis §13.2, "smoother variant"; thresholds per erratum A-19): a triangle mesh
follows the flow only at its vertices, so its volume error is O(edge²) of the *deformed*
edges. Edges stretched beyond ``refine × max(rest length, mean rest edge length)`` are split
at their **rest** midpoint, and the new vertex is placed by integrating that rest point with exactly the same
step sequence (``Φ``) as the original vertices — deterministic, so it lands where it would
have had the rest mesh been finer there from the start. Both triangles sharing the edge are
bisected (2-to-4, conforming, watertight); the rest volume is unchanged (new vertices lie on
flat rest edges). Passes repeat, longest edges first, until no edge exceeds the threshold.
"""

from __future__ import annotations

from dataclasses import dataclass
from dataclasses import field as _dc_field

import numpy as np

from . import _core
from ._advect import advect
from ._mesh import Mesh
from ._mesh import signed_volume as _volume
from ._validate import as_float_array, as_int
from .fields import Field, _positive, _real

__all__ = ["DeformReport", "StampReport", "deform", "stamp"]


@dataclass(frozen=True)
class DeformReport:
    """What :func:`deform` did. Volumes are signed (outward-wound meshes are positive), in the
    mesh's units cubed.

    Attributes
    ----------
    rest_volume : float
        Volume of the rest mesh (refinement adds vertices on flat rest edges, so it is the
        input's volume).
    volume : float
        Volume of the deformed mesh.
    relative_change : float
        ``volume / rest_volume − 1`` (NaN when ``rest_volume`` is 0).
    steps : int
        RK4 steps taken.
    vertices_added : int
        Vertices added by the refinement, over ``passes`` passes.
    passes : int
        Refinement passes that split at least one edge.
    integration_error : float or None
        With ``estimate=True``: the Richardson estimate ``(V_n − V_2n)/V_rest · 16/15`` of the
        part of ``relative_change`` due to time integration; else None.
    mesh_error : float or None
        With ``estimate=True``: ``relative_change − integration_error``, the part due to the
        triangle mesh (flat faces between advected vertices); else None.
    rest_vertices : ndarray (V', 3) float64 or None
        Rest positions of the output mesh's vertices (the input's, then the rest midpoints
        of the split edges), for re-running or checking the deformation.
    """

    rest_volume: float
    volume: float
    relative_change: float
    steps: int
    vertices_added: int
    passes: int
    integration_error: float | None = None  # relative, Richardson estimate (estimate=True)
    mesh_error: float | None = None  # relative_change − integration_error
    rest_vertices: np.ndarray | None = _dc_field(default=None, repr=False, compare=False)

    def __str__(self) -> str:
        s = (f"volume {self.rest_volume:.6g} → {self.volume:.6g} "
             f"(relative change {self.relative_change:+.3e}); {self.steps} RK4 steps; "
             f"{self.vertices_added} vertices added in {self.passes} passes")
        if self.integration_error is not None:
            s += (f"; integration {self.integration_error:+.2e}, "
                  f"mesh {self.mesh_error:+.2e}")
        return s


def _edges(F: np.ndarray):
    """Unique edges (m, 2), and the edge id of every face slot (nf, 3); slot k is the edge
    F[k] → F[k+1]."""
    e = np.stack([F, np.roll(F, -1, axis=1)], axis=-1).reshape(-1, 2)
    key = np.sort(e, axis=1)
    uniq, inv = np.unique(key, axis=0, return_inverse=True)
    return uniq, inv.reshape(-1, 3)


def _refine_pass(Vr, W, F, refine, mean_rest, phi):
    edges, slot = _edges(F)
    length = np.linalg.norm(W[edges[:, 0]] - W[edges[:, 1]], axis=1)
    rest = np.linalg.norm(Vr[edges[:, 0]] - Vr[edges[:, 1]], axis=1)
    long = np.flatnonzero(length > refine * np.maximum(rest, mean_rest))
    if len(long) == 0:
        return Vr, W, F, 0
    # faces of each edge
    order = np.argsort(slot.ravel(), kind="stable")
    ids = slot.ravel()[order]
    start = np.searchsorted(ids, np.arange(len(edges)))
    count = np.bincount(ids, minlength=len(edges))
    long = long[np.argsort(-length[long], kind="stable")]
    used = np.zeros(len(F), dtype=bool)
    pick_faces, pick_slots, pick_edges = [], [], []
    for e in long:
        fs = order[start[e]:start[e] + count[e]]
        faces = fs // 3
        if used[faces].any():
            continue
        used[faces] = True
        pick_edges.append(e)
        pick_faces.append(faces)
        pick_slots.append(fs % 3)
    pe = np.asarray(pick_edges)
    m = len(Vr) + np.arange(len(pe))
    mid = 0.5 * (Vr[edges[pe, 0]] + Vr[edges[pe, 1]])
    Vr = np.concatenate([Vr, mid])
    W = np.concatenate([W, phi(mid)])
    newm = np.repeat(m, [len(f) for f in pick_faces])
    faces = np.concatenate(pick_faces)
    slots = np.concatenate(pick_slots)
    rows = F[faces]
    p = rows[np.arange(len(rows)), slots]
    q = rows[np.arange(len(rows)), (slots + 1) % 3]
    r = rows[np.arange(len(rows)), (slots + 2) % 3]
    F = F.copy()
    F[faces] = np.c_[p, newm, r]
    F = np.concatenate([F, np.c_[newm, q, r]])
    return Vr, W, F, len(pe)


def _mesh_arrays(mesh):
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
    if len(F) and (F.min() < 0 or F.max() >= len(V)):
        raise ValueError("mesh: face indices out of range")
    return V, F


def deform(mesh, field: Field, duration, steps=None, *, refine=1.5, max_passes: int = 30,
           t0=0.0, estimate: bool = False, progress=False) -> tuple[Mesh, DeformReport]:
    """Deform a closed triangle mesh along a divergence-free field and report the volume.

    The vertices are advected with RK4 (:func:`spinal.advect`, default step rule); then, if
    ``refine`` is a number, every edge that the deformation stretched beyond
    ``refine × max(its rest length, mean rest edge length)`` is split at its rest midpoint,
    the new vertex integrated from the rest mesh with the same steps, and its two triangles
    bisected; repeated (at most ``max_passes`` passes) until no edge is too long. Edges that
    are long already at rest are split only where they stretch, so a mesh with uneven edges
    is not refined where the tool never reached. ``refine=None`` only advects.

    Parameters
    ----------
    mesh : spinal.Mesh, trimesh.Trimesh, or a ``(vertices, faces)`` pair
        A closed, consistently wound triangle mesh (the rest mesh; not modified).
    field, duration, steps, t0, progress : as in :func:`spinal.advect`.
    estimate : bool
        Also split the volume change into integration error (Richardson,
        ``(V_n − V_2n)·16/15`` from a rerun with twice the steps) and mesh error.

    Returns
    -------
    (Mesh, DeformReport)
        The deformed (refined) mesh and the volume report.
    """
    V, F = _mesh_arrays(mesh)
    if not isinstance(field, Field):
        raise TypeError(f"field: expected a spinal.fields.Field, got {type(field).__name__}")
    duration = _real(duration, "duration")
    t0 = _real(t0, "t0")
    n = field.steps(duration) if steps is None else as_int(steps, "steps")
    if n < 1:
        raise ValueError(f"steps: must be at least 1, got {n}")
    if refine is not None:
        refine = _positive(refine, "refine")
    max_passes = as_int(max_passes, "max_passes")

    def phi(x, n=n):
        return advect(x, field, duration, n, t0=t0)

    W = advect(V, field, duration, n, t0=t0, progress=progress)
    Vr, Fr, added, passes = V, F, 0, 0
    if refine is not None and len(F):
        e, _ = _edges(F)
        mean_rest = np.linalg.norm(V[e[:, 0]] - V[e[:, 1]], axis=1).mean()
        while passes < max_passes:
            Vr, W, Fr, k = _refine_pass(Vr, W, Fr, refine, mean_rest, phi)
            if k == 0:
                break
            added += k
            passes += 1
    rest, vol = _volume(Vr, Fr), _volume(W, Fr)
    change = vol / rest - 1 if rest != 0 else float("nan")
    integ = mesh_err = None
    if estimate:
        W2 = advect(Vr, field, duration, 2 * n, t0=t0)
        integ = (vol - _volume(W2, Fr)) / rest * 16 / 15
        mesh_err = change - integ
    return Mesh(W, Fr), DeformReport(rest, vol, change, n, added, passes, integ, mesh_err, Vr)


@dataclass(frozen=True)
class StampReport:
    """What :func:`stamp` did. Volumes are signed, in the mesh's units cubed; the arrays have
    one entry per frame (length ``frames``).

    Attributes
    ----------
    rest_volume, volume : float
        Volume of the input mesh and of the stamped mesh.
    relative_change : float
        ``volume / rest_volume − 1`` (NaN when ``rest_volume`` is 0).
    dent : ndarray (frames,) float64
        Volume removed by snapping the vertices inside the tool to its surface (≥ 0).
    time : ndarray (frames,) float64
        The moving time ``t`` of the protrusion: how long the tool's curl translation field
        (unit velocity along the motion) is integrated, so a length; 0 without contact.
    residual : ndarray (frames,) float64
        Volume after the frame minus volume before it, after the secant corrections.
    contact : ndarray (frames,) int64
        Number of vertices snapped to the tool in the frame.
    """

    rest_volume: float
    volume: float
    relative_change: float
    dent: np.ndarray
    time: np.ndarray
    residual: np.ndarray
    contact: np.ndarray


def stamp(mesh, start, end, radius, *, reach=None, frames: int = 10,
          iterations: int = 2) -> tuple[Mesh, StampReport]:
    """Press a sphere into a closed mesh in contact only (thesis §11.2.6, the "stamper";
    issue-4 brief §2.8), giving the dented volume back as a protrusion around the contact.

    The tool centre moves from ``start`` to ``end`` in ``frames`` equal moves. Each frame:

    1. vertices inside the tool snap to its surface; the dent ``δv`` is the change of the
       mesh's signed volume;
    2. over the triangles without a contact vertex, ``v_bary = max(v·n, 0)`` at the
       barycentre, ``v`` the curl :func:`spinal.fields.translation` field of the tool (static
       at the frame's centre, unit velocity along the motion, ``reach``);
    3. the vertices of the triangles with ``v_bary > 0`` move along ``v`` (one RK4 step) for
       ``t = δv / Σ A_tri v_bary``;
    4. ``iterations`` secant corrections of ``t`` on the measured volume.

    A volume *balance*, not a divergence-free flow: the volume is kept per frame up to the
    secant residual (reported); no vertex ends inside the tool.

    Parameters
    ----------
    mesh : spinal.Mesh, trimesh.Trimesh or (vertices, faces); closed, outward wound; not
        modified.
    start, end : (3,) tool centre at the first and last frame.
    radius : tool radius ρ > 0.
    reach : R > 0 of the protrusion field (default ``radius``).
    frames : number of moves ≥ 1.
    iterations : secant corrections per frame ≥ 0.

    Returns
    -------
    (Mesh, StampReport)
    """
    from .fields import _vec3

    V, F = _mesh_arrays(mesh)
    a, b = _vec3(start, "start"), _vec3(end, "end")
    rho = _positive(radius, "radius")
    reach = rho if reach is None else _positive(reach, "reach")
    frames = as_int(frames, "frames")
    if frames < 1:
        raise ValueError(f"frames: must be at least 1, got {frames}")
    iterations = as_int(iterations, "iterations")
    if iterations < 0:
        raise ValueError(f"iterations: must be ≥ 0, got {iterations}")
    W, rep = _core.stamp(V, F, tuple(a), tuple(b), rho, reach, frames, iterations)
    rest, vol = _volume(V, F), _volume(W, F)
    change = vol / rest - 1 if rest != 0 else float("nan")
    return Mesh(W, F), StampReport(rest, vol, change, rep[:, 0], rep[:, 1], rep[:, 2],
                                   rep[:, 3].astype(np.int64))
