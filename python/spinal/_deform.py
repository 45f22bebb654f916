"""``spinal.deform``: carry a closed triangle mesh along a divergence-free field, refining the
edges that the flow stretches while it integrates (Rust core, ``src/deform/refine/``).

Refinement (Zheng's thesis §13.2, with the smoother variant's placement): after every
integration step, an edge longer than ``refine × max(its rest length, mean rest edge)`` is
refined by Rivara's longest-edge bisection — the edge that ends its longest-edge propagation
path (the longest edge of both its triangles) is split, both triangles bisected (conforming,
watertight, no angle below half of the one it came from) — and the new vertex is the rest
midpoint carried by the same steps (``Φ(rest)``), then carried on with the mesh. After the
integration, edges that the flow bends without stretching them (``Φ`` of the rest midpoint
more than 0.06 of the edge from the chord: a press into a long face, a sharp bend that
folds flat faces over their neighbours) are split the same way
(``DeformReport.bend_vertices``). Where the flow tears an edge
apart (the tangential slip at the surface of a curl tool) the body's boundary runs along the
tool's surface between the two torn sides: the new vertex goes halfway along that path, onto
the material of one side or onto the tool's surface, where it moves with a blend of the two
sides' velocities (``DeformReport.slip_vertices``). Edge flips along that strip, and after
the integration edge collapses and vertex moves on the tool's surface (Hoppe et al., "Mesh
optimization", SIGGRAPH 1993), remove the slivers and folds that the strip's few rest points
give, keeping the mesh closed and consistently wound and its volume (``DeformReport.flips``,
``collapses``, ``moves``). The work is bounded by
``max_vertices`` and ``max_passes``; when edges remain too long at the end the report says so
and a :class:`RefinementWarning` is emitted.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass
from dataclasses import field as _dc_field
from typing import Literal

import numpy as np

from . import _core
from ._advect import MAX_STEPS, default_steps
from ._mesh import Mesh, mesh_arrays
from ._mesh import volumes_at_scale as _volumes
from ._progress import Progress, checked
from ._types import AnyMesh, Array, Float64Array, Int64Array, ProgressArg
from ._validate import as_bool, as_finite, as_int, as_real, as_vector
from .fields import Field

__all__ = ["DeformReport", "RefinementWarning", "StampReport", "deform", "stamp"]

# bounds of the stamper's work: frames per call, secant corrections per frame
MAX_FRAMES = 1_000_000
MAX_ITERATIONS = 1000
#: Each refinement pass halves the longest edges: 1000 passes is beyond any useful refinement.
MAX_PASSES = 1000


class RefinementWarning(UserWarning):
    """:func:`spinal.deform` stopped refining at its ``max_vertices`` (or ``max_passes``) bound
    with edges still longer than the threshold: the mesh is less resolved than asked for (see
    ``DeformReport.converged`` and ``edges_over_threshold``)."""


def _unscaled(volume: float, e: int) -> float:
    """A volume taken on vertices scaled by ``2**-e``, in the mesh's units (``±inf`` when
    it exceeds float64)."""
    with np.errstate(over="ignore", under="ignore"):
        return float(np.ldexp(volume, 3 * e))


@dataclass(frozen=True)
class DeformReport:
    """What :func:`deform` did. Volumes are signed (outward-wound meshes are positive), in the
    mesh's units cubed.

    Attributes
    ----------
    rest_volume : float
        Volume of the rest mesh (refinement adds vertices on flat rest edges and the
        ``collapses`` keep the rest volume, so it is the input's volume).
    volume : float
        Volume of the deformed mesh.
    relative_change : float
        ``volume / rest_volume − 1`` (NaN when ``rest_volume`` is 0).
    steps : int
        The RK4 step count of the call (given or the default rule); with a path tool the
        steps end at its breakpoints, so more are taken (``step_vertices`` has one entry
        per step taken), and ``spinal.advect(rest_vertices, field, duration, steps)``
        reproduces them.
    vertices_added : int
        Vertices added by the refinement, over ``passes`` passes, less the ``collapses``
        (``len(mesh.vertices) − len(input vertices)``).
    passes : int
        Refinement passes that split at least one edge.
    integration_error : float or None
        With ``estimate=True``: the Richardson estimate ``(V_n − V_2n)/V_rest · 16/15`` of the
        part of ``relative_change`` due to time integration; else None.
    mesh_error : float or None
        With ``estimate=True``: ``relative_change − integration_error``, the part due to the
        triangle mesh (flat faces between advected vertices); else None.
    rest_vertices : ndarray (V', 3) float64 or None
        Rest positions of the output mesh's vertices (the input's, then points of the split
        rest edges: the rest midpoint, or on an edge across a tool's surface the point of the
        edge placed halfway along its path, see ``torn_vertices``), for re-running or
        checking the deformation. Every vertex is the flow ``Φ`` of its rest position (near
        a curl tool's surface, the flow of the material of the side its rest position lies
        on), except the ``slip_vertices`` and ``chord_vertices``.
    converged : bool
        True when no edge is over the threshold at the end, no face has zero area and (with
        ``check="intersections"``) no faces cross. False when ``max_vertices`` or
        ``max_passes`` stopped the refinement with edges still too long or still bent (see
        ``bent_edges``), or the result has faces of zero area or crossing faces (a
        :class:`RefinementWarning` was emitted).
        Across a tool's slip every edge can be shortened (see ``torn_vertices``), so a
        refinement that no bound stops converges.
    edges_over_threshold : int
        Edges longer than the threshold at the end (0 when converged).
    max_vertices : int or None
        The vertex bound the refinement ran under (None without refinement).
    torn_vertices : int
        New vertices of edges that the tangential slip at a curl tool's surface tore apart
        (Zheng's thesis §12.1: only the normal velocity is continuous across it, so the
        material at rest inside the tool and outside it part along the surface). Such an
        edge's path runs from one end over its side's material to the surface, along the
        surface between the two torn sides, and over the other side's material to the other
        end. The material of a side is carried by that side's one-sided velocity ``v₊``
        (outside) or ``v₋`` (inside); a point of the surface by the blend
        ``v_s = (1 − s) v₊ + s v₋``, ``s ∈ [0, 1]``, which keeps it on the surface (``v₊`` and
        ``v₋`` share the normal part, the surface's own) — ``s = ½`` moves with the tool
        itself, and ``s`` from 0 to 1 sweeps the strip of tool surface between the torn
        sides. The new vertex is the point halfway along the path (by the chords between its
        images): a material point of one side, or a point of the surface with the mean blend
        of its neighbours along the path. Both halves are then about half as long, so
        bisection resolves every edge across the slip. Where the halfway point would land on
        a third vertex of the edge's triangles and join the other one by an edge longer than
        the split one (halving would only repeat an earlier split), the new vertex goes to the
        corner of the path nearest to it, where the path meets or leaves the tool's surface.
        Also counts the ``chord_vertices``.
    slip_vertices : int
        Vertices on a tool's surface at the end (carried with their blend ``s``, not the flow
        of their rest position).
    chord_vertices : int
        New vertices of edges of one side's material whose image of the rest midpoint fell
        farther than a quarter of the edge from the chord midpoint (a flow that the steps do
        not resolve): the chord midpoint, moved onto the nearest slip surface when one passes
        within the edge's length.
    flips : int
        Edges flipped along a tool's surface: the strip of the surface between the torn sides
        is filled by vertices of few rest points each, which bisection joins into slivers; an
        edge there is flipped where that raises the smaller smallest angle of its two
        triangles (Lawson's max-min angle flips), keeping the mesh closed and consistently
        wound, not folding, keeping the rest mesh's volume and changing the volume by at most
        1e-4 × the cube of the mean rest edge.
    flip_volume : float
        The change of the volume by the flips (the sum of their tetrahedra's signed volumes).
    collapses : int
        Edges collapsed along a tool's surface after the integration, each removing a vertex
        and two faces (Hoppe et al., "Mesh optimization", SIGGRAPH 1993): the edges of faces
        with a smallest angle under 1° or folded back against a neighbour (dihedral angle over
        120°) whose flips could not mend them. A collapse keeps the mesh closed, 2-manifold
        and consistently wound (the link condition), raises the faces' smallest angle or
        removes slivers or folds without creating others, leaves no edge over the threshold
        and keeps the rest mesh's volume; the surviving vertex lies on the tool's surface, at
        the point of the edge (moved onto the surface) that keeps the enclosed volume, within
        1e-3 × the cube of the mean rest edge. Only on a refinement that converged.
    moves : int
        Vertices of such faces left after the collapses that were moved on the tool's surface
        towards the centroid of their neighbours (with the same tests).
    collapse_volume : float
        The change of the volume by the collapses and moves (the sum of what each left).
    degenerate_faces : int
        Faces of the result with zero area (the cross product of two of their edges is zero
        in floating point).
    crossing_pairs : int or None
        With ``check="intersections"``: the pairs of faces of the result that cross
        (:meth:`spinal.Mesh.self_intersections`); else None (not looked for).
    bent_edges : int
        Edges the flow still bends at the end: ``Φ`` of the rest midpoint farther than 0.06
        of the edge from its chord midpoint (the flat faces then miss the deformed surface
        by about as much), or, with both ends away from any slip surface, a deviation
        ``δ`` that accounts for more than 2e-3 of the rest volume per input edge
        (``|δ · n| / 6``, ``n`` the sum of the edge's two face cross products
        ``(y − x) × (z − x)``: the volume between the flat faces and the quadratic patch
        through their corners and ``Φ`` of the edge midpoints is ``Σ δ · n / 6``; a twist
        loses volume this way while shearing each face by less than 0.06). After the
        integration such edges longer than a quarter of the mean rest edge are split — the
        terminal edge of their longest-edge path, at ``Φ`` of its rest midpoint — in
        rounds, until a round splits nothing, for at most ``max_passes`` rounds and within
        ``max_vertices``. Where the field is smooth (both ends and the rest midpoint away
        from any slip surface) an edge is split at ``Φ`` of its rest midpoint however far that
        lies from the chord (a twist turns a long edge's midpoint far off it). Near a slip
        surface an edge stays bent where its path ends at an edge whose ``Φ(rest midpoint)``
        is torn away from the chord (more than a quarter of the edge: a flow the steps do
        not resolve there); such edges are not part of ``converged``. Edges left bent
        because a bound stopped the rounds make ``converged`` false.
    bend_vertices : int
        Vertices those bending splits added (part of ``vertices_added``).
    step_vertices : ndarray (steps,) int64 or None
        Vertex count after each integration step (the last one after the bending splits and the collapses).
    timings : dict or None
        Wall time in seconds of each phase: ``"integrate"`` (the mesh's vertices),
        ``"refine"`` (edge tests, new vertices, splits), ``"volume"``, ``"estimate"``.
    """

    rest_volume: float
    volume: float
    relative_change: float
    steps: int
    vertices_added: int
    passes: int
    integration_error: float | None = None  # relative, Richardson estimate (estimate=True)
    mesh_error: float | None = None  # relative_change − integration_error
    rest_vertices: Float64Array | None = _dc_field(default=None, repr=False, compare=False)
    converged: bool = True
    edges_over_threshold: int = 0
    max_vertices: int | None = None
    torn_vertices: int = 0
    step_vertices: Int64Array | None = _dc_field(default=None, repr=False, compare=False)
    timings: dict[str, float] | None = _dc_field(default=None, repr=False, compare=False)
    slip_vertices: int = 0
    chord_vertices: int = 0
    flips: int = 0
    flip_volume: float = 0.0
    collapses: int = 0
    moves: int = 0
    collapse_volume: float = 0.0
    degenerate_faces: int = 0
    crossing_pairs: int | None = None
    bent_edges: int = 0
    bend_vertices: int = 0

    def __str__(self) -> str:
        s = (f"volume {self.rest_volume:.6g} → {self.volume:.6g} "
             f"(relative change {self.relative_change:+.3e}); {self.steps} RK4 steps; "
             f"{self.vertices_added} vertices added in {self.passes} passes")
        if self.edges_over_threshold:
            s += (f"; {self.edges_over_threshold} edges still over the threshold "
                  f"(max_vertices={self.max_vertices})")
        if self.degenerate_faces:
            s += f"; {self.degenerate_faces} faces of zero area"
        if self.crossing_pairs:
            s += f"; {self.crossing_pairs} pairs of faces cross"
        if self.integration_error is not None:
            s += (f"; integration {self.integration_error:+.2e}, "
                  f"mesh {self.mesh_error:+.2e}")
        return s


def deform(
    mesh: AnyMesh,
    field: Field,
    duration: float,
    steps: int | None = None,
    *,
    refine: float | None = 1.5,
    max_passes: int = 30,
    t0: float = 0.0,
    estimate: bool = False,
    progress: ProgressArg = False,
    max_vertices: int | None = None,
    check: bool | Literal["intersections"] = True,
) -> tuple[Mesh, DeformReport]:
    """Deform a closed triangle mesh along a divergence-free field and report the volume.

    The vertices are advected with RK4 (the steps of :func:`spinal.advect`, default step
    rule). With ``refine`` a number ``τ ≥ 1``, after every step each edge longer than
    ``τ × max(its rest length, mean rest edge length)`` is split at its rest midpoint — the
    new vertex is that point carried by the steps so far, then carried on with the mesh —
    longest edges first, both triangles bisected (Zheng's thesis §13.2; Rivara's
    longest-edge bisection keeps triangles from getting thinner). Edges that are long already
    at rest are split only where they stretch, so a tool that never reaches the mesh adds no
    vertex. Where the flow tears an edge apart (across the tangential slip at the surface of
    a curl tool such as :func:`spinal.fields.translation`, whose field is only continuous in
    its normal part there) the body's boundary runs along the tool's surface between the
    torn sides: the new vertex goes halfway along that path, onto one side's material or onto
    the tool's surface, which it then follows with a blend of the two sides' velocities (see
    ``DeformReport.torn_vertices``). Slivers and folded faces along that strip are mended by
    edge flips during the integration and, on a converged refinement, by edge collapses and
    vertex moves on the tool's surface afterwards, each keeping the mesh closed and
    consistently wound and its volume (``DeformReport.flips``, ``collapses``, ``moves``).
    ``refine=None`` only advects.

    The work is bounded: at most ``max_vertices`` vertices and ``max_passes`` passes after
    each step. When edges remain too long at the end because a bound stopped the refinement,
    the report has ``converged=False`` and the count of those edges, and a
    :class:`spinal.RefinementWarning` is emitted.

    Parameters
    ----------
    mesh : spinal.Mesh, trimesh.Trimesh, or a ``(vertices, faces)`` pair
        A closed, consistently wound, edge-manifold triangle mesh (the rest mesh; not
        modified).
    field, duration, steps, t0 : as in :func:`spinal.advect`.
    refine : float ≥ 1 or None
        The split threshold τ (default 1.5, Zheng's "1.5 × the mean initial edge length").
    max_passes : int in 0 … 1000
        Refinement passes after each step (each splits a set of edges with disjoint
        triangles).
    max_vertices : int, optional
        Upper bound of the refined mesh's vertex count (default ``8 × len(vertices)``).
    estimate : bool
        Also split the volume change into integration error (Richardson,
        ``(V_n − V_2n)·16/15`` from a rerun of the refined rest mesh with twice the steps) and
        mesh error.
    progress : bool or callable
        As in :func:`spinal.advect`: a bar, or ``progress(done_steps, total_steps)``. Ctrl-C
        stops the call between steps (``KeyboardInterrupt``).
    check : bool or "intersections"
        Refuse (``ValueError`` naming ``mesh``) a mesh that does not bound a solid: an open
        mesh (an edge in one face), an edge in more than two faces, inconsistently wound faces
        or a mesh wound inwards (negative enclosed volume). The volume of such a mesh means
        nothing, so neither does the report's ``relative_change``. ``check=False`` deforms it
        anyway (the vertices move the same); an edge in more than two faces or two faces
        running through an edge in the same direction are refused either way.
        ``"intersections"`` checks the input as ``True`` does and also looks for crossing
        faces in the result (``DeformReport.crossing_pairs``, an exact test in
        ``O(F log F)``).

    Returns
    -------
    (Mesh, DeformReport)
        The deformed (refined) mesh and the volume report.
    """
    V, F = mesh_arrays(mesh)
    if not isinstance(field, Field):
        raise TypeError(f"field: expected a spinal.fields.Field, got {type(field).__name__}")
    duration = as_finite(duration, "duration")
    t0 = as_finite(t0, "t0")
    n = default_steps(field, duration, V, t0) if steps is None else as_int(steps, "steps")
    if not 1 <= n <= MAX_STEPS:
        raise ValueError(f"steps: must be in 1 … {MAX_STEPS}, got {n}")
    if refine is not None:
        refine = as_real(refine, "refine")  # the core checks refine ≥ 1
    max_passes = as_int(max_passes, "max_passes", 0, MAX_PASSES, out_of_bounds=lambda x: (
        f"must be ≥ 0 and at most {MAX_PASSES}, got {x}"))
    if max_vertices is None:
        max_vertices = 8 * len(V)
    else:
        max_vertices = as_int(max_vertices, "max_vertices")
        if max_vertices < len(V):
            raise ValueError(f"max_vertices: must be at least the mesh's {len(V)} vertices, "
                             f"got {max_vertices}")
    estimate = as_bool(estimate, "estimate")
    intersections = isinstance(check, str) and check == "intersections"
    if not intersections:
        if isinstance(check, str):
            raise ValueError(f"check: expected True, False or 'intersections', got {check!r}")
        check = as_bool(check, "check")
    progress = checked(progress)
    bar: list[Progress] = []  # the progress report, made when the core reports the step count

    def tick(done: int, total: int) -> None:
        if not bar:
            bar.append(Progress(progress, total, "deform", "step"))
        bar[0].update(done)

    try:
        W, Vr, Fr, counts, stats = _core.deform_mesh(
            V, F, field, {"t0": t0, "duration": duration, "steps": n, "refine": refine,
                          "max_vertices": max_vertices, "max_passes": max_passes,
                          "check": bool(check)},
            None if progress is False else tick)
    finally:
        if bar:
            bar[0].close()
    torn, over, bounded = stats.torn, stats.over_threshold, stats.bounded
    on_slip, chord, bent = stats.slip_vertices, stats.fallback, stats.bent
    flips, flip_volume = stats.flips, stats.flip_volume
    collapses, moves, collapse_volume = stats.collapses, stats.moves, stats.collapse_volume
    passes, bent_added = stats.passes, stats.bend_splits
    t_int, t_ref = stats.time_integrate, stats.time_refine
    clock = time.perf_counter()
    e, (rest, vol) = _volumes(Fr, Vr, W)
    change = vol / rest - 1 if rest != 0 else float("nan")
    rest, vol = _unscaled(rest, e), _unscaled(vol, e)
    timings = {"integrate": t_int, "refine": t_ref, "volume": time.perf_counter() - clock,
               "estimate": 0.0}
    integ = mesh_err = None
    if estimate:
        clock = time.perf_counter()
        # both runs with the mesh's own integrator (vertices at a tool's surface carried by
        # their side's velocity; spinal.advect's RK4 stages step across the surface there)
        def rerun(steps: int) -> np.ndarray:
            return _core.deform_mesh(Vr, Fr, field, {
                "t0": t0, "duration": duration, "steps": steps, "refine": None,
                "max_vertices": len(Vr), "max_passes": 0, "check": False})[0]

        W1 = W if torn == 0 else rerun(n)
        W2 = rerun(2 * n)
        _, (scaled_rest, v1, v2) = _volumes(Fr, Vr, W1, W2)
        integ = (v1 - v2) / scaled_rest * 16 / 15
        mesh_err = change - integ
        timings["estimate"] = time.perf_counter() - clock
    out = Mesh(W, Fr)
    tri = W[Fr]
    degenerate = int(np.count_nonzero(
        ~np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]).any(axis=1)))
    crossing = len(out.self_intersections()) if intersections else None
    converged = not bounded and degenerate == 0 and not crossing
    if bounded and over:
        warnings.warn(RefinementWarning(
            f"deform: {over} edges are still longer than refine × their rest length (the "
            f"refinement stopped at max_vertices={max_vertices} or max_passes={max_passes} per "
            f"step); raise max_vertices or max_passes"), stacklevel=2)
    elif bounded:
        warnings.warn(RefinementWarning(
            f"deform: {bent} edges are still bent by the flow (the bending splits stopped at "
            f"max_vertices={max_vertices} or after max_passes={max_passes} rounds); raise "
            f"max_vertices or max_passes"), stacklevel=2)
    if degenerate or crossing:
        what = [f"{degenerate} faces of zero area"] if degenerate else []
        what += [f"{crossing} pairs of crossing faces"] if crossing else []
        warnings.warn(RefinementWarning(
            f"deform: the result has {' and '.join(what)} (see Mesh.self_intersections); "
            f"more steps or a smoother tool may avoid them"), stacklevel=2)
    report = DeformReport(rest, vol, change, n, len(Vr) - len(V), passes, integ, mesh_err, Vr,
                          converged, over, max_vertices if refine is not None else None, torn,
                          counts, timings, on_slip, chord, flips, flip_volume, collapses,
                          moves, collapse_volume, degenerate, crossing, bent,
                          bent_added)
    return out, report


def _positive(x: object, name: str) -> float:
    x = as_finite(x, name)
    if not x > 0:
        raise ValueError(f"{name}: must be positive, got {x}")
    out: float = x
    return out


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
    dent: Float64Array
    time: Float64Array
    residual: Float64Array
    contact: Int64Array


def stamp(
    mesh: AnyMesh,
    start: Array,
    end: Array,
    radius: float,
    *,
    reach: float | None = None,
    frames: int = 10,
    iterations: int = 2,
    progress: ProgressArg = False,
) -> tuple[Mesh, StampReport]:
    """Press a sphere into a closed mesh in contact only (thesis §11.2.6, the "stamper"),
    giving the dented volume back as a protrusion around the contact.

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
    frames : number of moves, 1 … 1,000,000.
    iterations : secant corrections per frame, 0 … 1000.
    progress : bool or callable
        Report the frames done: True shows a bar (tqdm when installed, in a terminal or a
        notebook) or a line on stderr; a callable is called as ``progress(done, frames)``
        after every frame.

    Ctrl-C stops it between frames (``KeyboardInterrupt``). A tool that swallows every vertex
    of the mesh or touches every triangle in a frame raises ``ValueError`` naming ``radius``;
    a dent with no free triangle within ``reach`` facing the tool's field (nothing to carry
    the protrusion) raises ``ValueError`` naming ``reach``.

    Returns
    -------
    (Mesh, StampReport)
    """
    V, F = mesh_arrays(mesh)
    a, b = as_vector(start, "start"), as_vector(end, "end")
    rho = _positive(radius, "radius")
    reach = rho if reach is None else _positive(reach, "reach")
    frames = as_int(frames, "frames", 1, MAX_FRAMES, out_of_bounds=lambda x: (
        f"must be at least 1 and at most {MAX_FRAMES:,}, got {x}"))
    iterations = as_int(iterations, "iterations", 0, MAX_ITERATIONS, out_of_bounds=lambda x: (
        f"must be ≥ 0 and at most {MAX_ITERATIONS}, got {x}"))
    progress = checked(progress)
    with Progress(progress, frames, "stamp", "frame") as bar:
        options = {"start": tuple(a), "end": tuple(b), "radius": rho, "reach": reach,
                   "frames": frames, "iterations": iterations}
        W, rep = _core.stamp(V, F, options,
                             (lambda done, total: bar.update(done)) if bar else None)
    e, (rest, vol) = _volumes(F, V, W)
    change = vol / rest - 1 if rest != 0 else float("nan")
    rest, vol = _unscaled(rest, e), _unscaled(vol, e)
    return Mesh(W, F), StampReport(rest, vol, change, rep[:, 0], rep[:, 1], rep[:, 2],
                                   rep[:, 3].astype(np.int64))
