"""The implementation of :mod:`spinal.fields` (see its documentation); the public names are
re-exported there."""

from __future__ import annotations

import functools
import numbers
from collections.abc import Iterable

import numpy as np

from . import _core
from ._core import Field
from ._mesh import mesh_arrays
from ._progress import Progress, checked
from ._validate import (
    as_bool,
    as_finite,
    as_float_array,
    as_int,
    as_points,
    as_positive,
    as_real,
    as_vector,
)


def _recorded(ctor):
    """The constructor, with the call remembered by the field it returns: a field pickles as
    the calls that built it (``Field.__reduce__`` → :func:`_rebuild`)."""

    @functools.wraps(ctor)
    def build(*args, **kwargs):
        # a progress report does not change the field: not part of its recipe
        kept = {k: v for k, v in kwargs.items() if k != "progress"}
        return ctor(*args, **kwargs)._with_recipe(ctor.__name__, args, kept)

    return build


def _rebuild(recipe) -> Field:
    """The field of a pickled recipe: the sum of ``name(*args, **kwargs)`` over its calls."""
    out = _core.field_zero()
    for name, args, kwargs in recipe:
        out = out + globals()[name](*args, **kwargs)
    return out


def _opt(x, name: str) -> float | None:
    return None if x is None else as_real(x, name)


def _power(x) -> int:
    return as_int(x, "falloff_power")


@_recorded
def translation(center, radius, velocity, *, reach=None, falloff_power: int = 2,
                moving: bool = True) -> Field:
    """A spherical tool moving with constant ``velocity``, pushing the material around it.

    Curl field (thesis eq. 12.1–12.2, corrected sign and scale)::

        V = (e^{p−1}/R^p) [ e u + (p/2) sgn(d) ((n·u) Y − (n·Y) u) ]   for |d| < R, else 0

    with ``Y = X − c(t)``, ``c(t) = center + velocity·t`` (``moving=False``: the tool stays at
    ``center``), ``d = |Y| − radius``, ``n = Y/|Y|``, ``e = R − |d|``, ``R = reach``
    (default: ``radius``, which keeps a 40k-vertex icosphere's volume error below 1e-4; the
    0.5·radius does not). On the tool surface the normal velocity equals ``u·n``:
    material neither enters the tool nor separates from it.

    Parameters
    ----------
    center : (3,) tool centre at t = 0.
    radius : tool radius ρ > 0.
    velocity : (3,) tool velocity (length/time); zero gives the zero field.
    reach : R > 0, width of the region around the tool that moves.
    falloff_power : p in {2, 3, 4}; 2 is the thesis's ``(R − |d|)²`` (C⁰ at ``|d| = R``).
    """
    return _core.field_translation(
        as_vector(center, "center"), as_real(radius, "radius"), as_vector(velocity, "velocity"),
        _opt(reach, "reach"), _power(falloff_power), as_bool(moving, "moving"))


@_recorded
def rotation(center, radius, axis, angular_speed, *, pivot=None, reach=None,
             falloff_power: int = 2) -> Field:
    """A spherical tool turning at ``angular_speed`` (rad/time, right-handed) about ``axis``
    through ``pivot`` (default: its centre, a tool spinning in place).

    Curl field (thesis eq. 12.3, corrected scale), with ``Y = X − pivot``, ``Ω = ω a`` and
    ``d``, ``n`` measured from the tool (whose centre orbits the pivot when off it)::

        V = (e^{p−1}/(3R^p)) [ p sgn(d) n × (|Y|²Ω − (Ω·Y)Y) + 3 e Ω × Y ]

    On the tool surface the normal velocity equals ``(Ω × Y)·n``. A tool centred on the pivot
    gives a pure swirl ``h(r) a × Y`` (zero normal velocity, an exact rotation on every
    sphere about the pivot).
    """
    return _core.field_rotation(
        as_vector(center, "center"), as_real(radius, "radius"), as_vector(axis, "axis"),
        as_real(angular_speed, "angular_speed"),
        None if pivot is None else as_vector(pivot, "pivot"), _opt(reach, "reach"),
        _power(falloff_power))


def _swirl(center, axis, rate, radius, form, bend: bool) -> Field:
    return _core.field_swirl(as_vector(center, "center"), as_vector(axis, "axis"),
                             as_real(rate, "rate"), as_real(radius, "radius"), form, bend)


@_recorded
def twist(center, axis, rate, radius, *, form: str = "rate") -> Field:
    """Twist about ``axis`` through ``center``: angle rate ``κ z`` (rad/time) at height
    ``z = a·(X − center)``, fading to 0 at distance ``radius`` from the centre.

    ``form="rate"``: ``v = κ z (1 − r/R)² a × Y`` (no counter-rotation);
    ``form="curl"``: the thesis's ``−(κ/(4R²)) curl((R − r)² z (Y × a) × Y)`` =
    ``κ z (1 − r/R)(1 − 3r/(2R)) a × Y`` (turns backwards for ``r > 2R/3``).
    Every sphere about the centre turns rigidly: the exact flow is a rotation by ``h·t``.
    """
    return _swirl(center, axis, rate, radius, form, False)


@_recorded
def bend(center, axis, rate, radius, *, form: str = "rate") -> Field:
    """The thesis's "bend" (eq. 12.6, a differential swirl): angle rate ``β r²`` about
    ``axis`` through ``center``, ``r = |X − center|``, fading to 0 at ``radius``.

    ``form="rate"``: ``v = β r² (1 − r/R)² a × Y``; ``form="curl"``:
    ``−(β/(5R²)) curl((R − r)² r² (Y × a) × Y)`` = ``β r² (1 − r/R)(1 − 7r/(5R)) a × Y``.
    A rod through the centre (perpendicular to the axis) winds into a spiral.
    """
    return _swirl(center, axis, rate, radius, form, True)


@_recorded
def sphere(center, radius, velocity, *, reach=None, blend: str = "c1",
           moving: bool = True) -> Field:
    """von Funck's region translation around a sphere (``r_i = radius``,
    ``r_o = radius + reach``): ``v = ∇p × ∇q`` with ``p = (1 − D) N·Y``, ``q = (1 − D) B·Y``::

        v = (1 − D)² u + (1 − D) D′ [ (n·u) Y − (n·Y) u ]

    rigid (``v = u``) inside the sphere, zero beyond ``radius + reach``.
    """
    return _core.field_sphere(
        as_vector(center, "center"), as_real(radius, "radius"), as_vector(velocity, "velocity"),
        _opt(reach, "reach"), blend, as_bool(moving, "moving"))


@_recorded
def capsule(start, end, radius, velocity, *, reach=None, blend: str = "c1",
            moving: bool = True) -> Field:
    """Region translation around a capsule (segment ``start``–``end``, ``radius``): the exact
    distance-field extension of :func:`sphere` to a free-form tool, ``Y = X − midpoint``,
    ``d`` the capsule's signed distance, ``n = ∇d``. Divergence-free for any C¹ distance.
    """
    return _core.field_capsule(
        as_vector(start, "start"), as_vector(end, "end"), as_real(radius, "radius"),
        as_vector(velocity, "velocity"), _opt(reach, "reach"), blend, as_bool(moving, "moving"))


@_recorded
def strip(start, end, radius, velocity, *, kind: str = "along", reach=None,
          blend: str = "c1") -> Field:
    """A straight strip (a capsule from ``start`` to ``end``) moving the material around it
    (thesis §11.2.2–11.2.3; type I moves the material along the strip, type II across it).

    ``kind="along"`` (type I, "sticking"): ``velocity`` parallel to the axis; the material
    around slides along the strip (the :func:`capsule` field, static).
    ``kind="across"`` (type II, "sweeping"): ``velocity`` perpendicular to the axis;
    ``p = s σ(X)`` (arc length of the closest axis point), ``q = (1 − D) U·(X − start)``,
    ``U = m̂ × t``; the field is zero beyond the end planes (a tangential jump only).
    For a curved axis (type I) see :func:`strip_curve`.
    """
    return _core.field_strip(
        as_vector(start, "start"), as_vector(end, "end"), as_real(radius, "radius"),
        as_vector(velocity, "velocity"), kind, _opt(reach, "reach"), blend)


@_recorded
def torus(center, axis, major, minor, speed, *, reach=None, blend: str = "c1",
          moving: bool = True) -> Field:
    """A torus (major radius ``major``, tube radius ``minor``) moving along its ``axis`` with
    ``speed`` (thesis §11.2.4; the two half-torus fields summed in closed form)::

        v = s (R_t/ρ) [ (1 − D) k + D′ (ρ − R_t) e_θ × n ]

    with ``ρ`` the distance to the axis. Needs ``minor + reach < major``.
    """
    return _core.field_torus(
        as_vector(center, "center"), as_vector(axis, "axis"), as_real(major, "major"),
        as_real(minor, "minor"), as_real(speed, "speed"), _opt(reach, "reach"), blend,
        as_bool(moving, "moving"))


@_recorded
def strip_curve(points, radius, speed, *, reach=None, blend: str = "c1") -> Field:
    """A strip of type I along a curved axis (thesis §11.2.2, "sticking", type I): the material
    within ``radius`` of the axis flows along it at ``speed`` (length/time, from
    ``points[0]`` towards ``points[-1]``; negative: backwards), leaves at the head, comes back
    outside (within ``radius + reach``) and re-enters at the tail. Static (the strip does not
    move); :func:`strip` with ``kind="along"`` is the straight special case.

    **Axis.** The clamped C² cubic spline ``γ`` through ``points`` in cumulative chord length
    ``S``, with the unit end tangents of :func:`spinal.estimate_tangents` (the tangents of
    :func:`spinal.frames`) as end derivatives. ``c(X) = γ(s(X))`` is the closest point of the
    spline (``(X − γ)·γ′ = 0``), ``r = |X − c(X)|``, ``T = γ′/|γ′|`` at ``s(X)``.

    **Field** (thesis: ``p = (1 − D) N·(X − c(X))``, ``q = (1 − D) B·(X − c(X))`` with ``(N, B)``
    the rotation-minimizing frame, ``v = ∇p × ∇q``). In tube coordinates ``X = γ + aN + bB``
    an RMF gives ``∇a = N``, ``∇b = B`` exactly (it does not turn about ``T``), hence::

        v = speed · (1 − D)(1 − D − r D′) · T(s(X))          D = b(clamp((r − ρ)/R_f, 0, 1))

    the same for every RMF (they differ by a constant turn), so no frame is stored; beyond the
    end planes the foot point is the end sample and ``v`` is :func:`sphere`'s field about it
    with velocity ``speed·T_end`` (continuous across the end planes). Exactly divergence-free:
    ``div(J(r) T) = J′ ∇r·T + J T′·∇s = 0`` (``∇r ⟂ T``, ``∇s ∥ T ⟂ T′``). Inside the tube
    ``v = speed·T``; the flux through each cross-section is zero. ``tests/deform/test_deform_tools.py``
    checks it against ``∇p × ∇q`` built from double-reflection frames by finite differences.

    Parameters
    ----------
    points : (n, 3) axis samples, n ≥ 2, no repeated consecutive points.
    radius : ρ > 0, the tube that flows rigidly along the axis.
    speed : flow speed inside the tube.
    reach : R_f > 0, width of the return-flow region (default ``radius``).
    blend : "c1" (``4σ³ − 3σ⁴``, v continuous) or "linear".

    The closest point must be unique within ``radius + reach``: the axis may not bend with
    curvature ``κ`` such that ``κ·(radius + reach + segment length) ≥ 1``, nor come back within
    ``2(radius + reach)`` of itself (between parts more than ``π(radius + reach)`` apart
    along it); both raise ``ValueError`` naming ``points``. Both are checked on 16 points per
    segment (the second on a uniform grid of cells of size ``2(radius + reach)``, a cost about
    linear in the number of samples).
    """
    return _core.field_strip_curve(as_points(points, "points"), as_real(radius, "radius"),
                                   as_real(speed, "speed"), _opt(reach, "reach"), blend)


def _spline_prefilter(values: np.ndarray) -> np.ndarray:
    """Coefficients (n + 2 per axis, one ghost layer each side) of the natural cubic B-spline
    interpolating ``values`` on a unit grid: per axis ``c_0 = d_0``, ``c_{n−1} = d_{n−1}``,
    ``c_{i−1} + 4c_i + c_{i+1} = 6d_i`` inside, ghosts ``c_{−1} = 2c_0 − c_1`` (zero second
    derivative at the end nodes). Solved in the core, line by line in parallel."""
    return _core.field_grid_coefficients(np.ascontiguousarray(values, dtype=np.float64))


def _grid_field(values, origin, h, velocity, center, reach, blend, moving, name):
    """The tool of a sampled distance: the default centre and reach from the samples, the
    B-spline coefficients, then the core (which checks the spacing against the reach and that
    the support stays inside the grid)."""
    u = as_vector(velocity, "velocity")
    coef, c, reach = _grid_spline(values, origin, h, center, reach)
    return _core.field_grid(coef, {"origin": origin, "spacing": h, "velocity": u, "center": c,
                                   "reach": reach, "blend": blend,
                                   "moving": as_bool(moving, "moving"), "name": name})


def _grid_spline(values, origin, h, center, reach):
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
        reach = float((np.linalg.norm(nodes - c, axis=1) - values[values <= 0]).max())
    else:
        reach = as_real(reach, "reach")
    return _spline_prefilter(values), c, reach


@_recorded
def sdf_tool(grid, origin, spacing, velocity, *, center=None, reach=None, blend: str = "c1",
             moving: bool = True) -> Field:
    """A free-form tool given by its signed distance sampled on a grid, translating with
    ``velocity``: Zheng's extended spherical field with the object's distance (thesis §11.2.1;
    the distance-field extension of :func:`sphere`)::

        p = (1 − D(d)) N·Y,  q = (1 − D(d)) B·Y,  Y = X − C,  N × B = u/|u|
        v = ∇p × ∇q = (1 − D)² u + (1 − D) D′ [ (∇d·u) Y − (∇d·Y) u ]

    with ``D = b(clamp(d/R_f, 0, 1))``: the material inside the tool (``d ≤ 0``) moves rigidly
    with ``u``, the field vanishes where ``d ≥ reach``. ``d`` is the C² tricubic B-spline
    interpolating the samples (natural end conditions) and ``∇d`` its exact gradient, so ``v``
    is exactly divergence-free for the interpolated distance (``∇p × ∇q`` of C² scalars); the
    sampling only decides which divergence-free field it is. Evaluated in Rust
    (``src/deform/grid.rs``); cells whose B-spline coefficients are all ``≥ reach`` are
    skipped (the basis is a partition of unity, so ``d ≥ reach`` there).

    A sphere's sampled distance reproduces :func:`sphere` with a 3rd-order error in the grid
    spacing (measured in ``tests/deform/test_deform_tools.py``).

    RK4 is only about 3rd order on this field: ``v`` uses ``∇d``, which is C¹ (the cubic
    B-spline's second derivatives jump across cell faces), so ``v``'s second derivatives jump
    there and each step across a face has an O(h³) local error; a path line crosses a fixed
    number of faces, so the global error falls about 8× per halving of the step where it
    crosses faces and 16× where it does not (measured for :func:`sdf_curl`: ratios 4.6–18,
    mean order 3.3, ``tests/deform/test_deform_curl.py``).

    Parameters
    ----------
    grid : (nx, ny, nz) signed distances (negative inside the tool, length units) at the
        nodes ``origin + (i, j, k)·spacing``; at least 8 nodes per axis, finite.
    origin : (3,) position of node (0, 0, 0).
    spacing : node spacing h > 0 (cubic cells); must be at most ``reach/4``.
    velocity : (3,) tool velocity (length/time).
    center : (3,) the tool's centre C (default: the centroid of the inside, the nodes weighted
        by the volume fraction ``clamp(1/2 − d/h, 0, 1)`` of their cells).
    reach : R_f > 0 (default: the tool's bounding radius about C estimated from the samples,
        ``max(|x_i − C| − d_i)`` over the nodes inside; exact for a sphere).
    blend : "c1" or "linear".
    moving : the tool (grid and centre) moves, ``d(X − u t)``; False keeps it at rest.

    The distance must be at least ``reach`` on the grid's outer cells (the support may not
    reach the grid's edge): ``ValueError`` naming ``grid`` otherwise.
    """
    a, o, h = _sdf_samples(grid, origin, spacing)
    return _grid_field(a, o, h, velocity, center, reach, blend, moving, "sdf_tool")


def _sdf_samples(grid, origin, spacing):
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


def _closed_mesh(mesh):
    """Vertices, faces and the enclosed volume's centroid of a closed, outward-wound mesh
    (the core checks it, naming ``mesh``)."""
    V, F = mesh_arrays(mesh)
    _, centroid = _core.mesh_closed_centroid(V, F)
    return V, F, np.asarray(centroid)


@_recorded
def mesh_tool(mesh, velocity, *, reach=None, resolution: int = 64, center=None,
              blend: str = "c1", moving: bool = True, progress=False) -> Field:
    """A free-form tool given as a closed triangle mesh, translating with ``velocity``: the
    field of :func:`sdf_tool` with the mesh's signed distance sampled on a grid.

    The grid covers the mesh's bounding box padded by ``reach + 4·spacing`` on every side,
    with ``resolution`` nodes along its longest side; the distances come from
    ``igl.signed_distance`` (libigl, pseudonormal sign; needs ``pip install libigl``), the
    interpolation and evaluation from :func:`sdf_tool`.

    Parameters
    ----------
    mesh : a spinal.Mesh, a trimesh.Trimesh or ``(vertices, faces)``: watertight, consistently
        oriented outwards (else ``ValueError`` naming ``mesh``).
    velocity : (3,) tool velocity.
    reach : R_f > 0 (default: the bounding radius ``max |v_i − C|``, so a sphere mesh of
        radius ρ gives :func:`sphere`'s default ``reach = ρ``).
    resolution : nodes along the longest side, 16 … 256; the spacing must come out at most
        ``reach/4`` (``ValueError`` naming ``resolution`` otherwise).
    center : (3,) the tool's centre C (default: the centroid of the enclosed volume).
    blend, moving : as for :func:`sdf_tool`.
    progress : bool or callable
        Report the grid nodes sampled (the long part at high resolution: 250³ nodes take
        minutes): ``True`` shows a bar (tqdm when installed, in a terminal or a notebook)
        or a line on stderr at every tenth; a callable is called as ``progress(done,
        nodes)``. The distances are then sampled in slabs of grid planes (at least 2¹⁶
        nodes and 32 per face), between which reports come and Ctrl-C stops the call;
        without ``progress`` they are sampled in one call to libigl, which Ctrl-C cannot
        stop.
    """
    values, origin, h, c, rf = _mesh_samples(mesh, reach, resolution, center, progress)
    return _grid_field(values, origin, h, velocity, c, rf, blend, moving, "mesh_tool")


def _mesh_samples(mesh, reach, resolution, center, progress):
    """The signed distance of a closed mesh sampled on the grid of :func:`mesh_tool`:
    samples, origin, spacing, centre and reach."""
    progress = checked(progress)
    V, F, centroid = _closed_mesh(mesh)
    c = centroid if center is None else as_vector(center, "center")
    rf = float(np.linalg.norm(V - c, axis=1).max()) if reach is None else as_real(reach, "reach")
    if not rf > 0:
        raise ValueError(f"reach: must be positive, got {rf}")
    res = resolution
    if isinstance(res, bool) or not isinstance(res, numbers.Integral):
        raise TypeError(f"resolution: expected an integer, got {type(res).__name__}")
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


def sum(fields: Iterable[Field]) -> Field:
    """The sum of fields (still divergence-free; velocities add where supports overlap)."""
    out = _core.field_zero()
    for i, f in enumerate(fields):
        if not isinstance(f, Field):
            raise TypeError(f"fields: item {i} is a {type(f).__name__}, not a spinal.fields.Field")
        out = out + f
    return out


@_recorded
def along_path(points, radius, duration, *, kind: str = "translate", tool: str = "push",
               rate=0.0, frames=None, t0=0.0, reach=None, falloff_power: int = 2,
               blend: str = "c1") -> Field:
    """A spherical tool travelling along a spine from ``points[0]`` (at time ``t0``) to
    ``points[-1]`` (at ``t0 + duration``) at constant speed ``u = L/duration`` in chord
    length ``L``, deforming the material around it; at rest (zero field) outside that time.

    Pose: in segment ``k``, ``λ = (σ − S_k)/ΔS_k`` with ``S_k`` the
    cumulative chord lengths and ``σ = u (t − t0)``,

    * centre ``o(σ)``: cubic Hermite through ``x_k, x_{k+1}`` with tangents ``t_k ΔS_k,
      t_{k+1} ΔS_k`` (exactly linear on a straight spine), velocity ``ȯ = u do/dσ``;
    * frame ``Q(σ) = F_k Exp(λ Θ_k)``, ``Θ_k = Log(F_kᵀ F_{k+1})``, ``F_k = [r_k s_k t_k]``
      the rotation-minimizing frames (``frames``, default :func:`spinal.frames` of the
      points), world angular velocity ``ω = u F_k Θ_k/ΔS_k``.

    The field at time ``t`` is a sum of divergence-free fields frozen at the pose:

    * ``tool="push"``: the curl :func:`translation` tool at ``o`` with velocity ``ȯ`` (a solid
      sphere pushing the material; normal velocity ``ȯ·n`` on its surface), or
      ``tool="carry"``: the :func:`sphere` region translation (the material inside the sphere
      moves rigidly with ``ȯ``, a point at the centre follows the path);
    * ``kind="rotate"`` adds the curl :func:`rotation` with ``Ω = ω`` about ``o`` (the region
      turns with the frames); ``kind="twist"`` adds a :func:`twist` about the moving tangent
      ``t`` with ``rate`` κ (rad/(length·time)); ``kind="bend"`` a :func:`bend` about the
      moving reference vector ``r`` with ``rate`` β (rad/(length²·time)); both swirls have
      the ball support ``radius + reach`` about ``o``.

    The velocity of the pose jumps in its derivative at the sample times
    (:meth:`Field.breakpoints`): :func:`spinal.advect` ends steps there to keep RK4 4th order.

    Parameters
    ----------
    points : (n, 3) spine samples, n ≥ 2, no repeated consecutive points.
    radius : tool radius ρ > 0.
    duration : time to travel the whole spine, > 0.
    kind : "translate", "rotate", "twist" or "bend".
    tool : "push" (curl tool) or "carry" (region translation).
    rate : twist or bend rate for ``kind="twist"``/``"bend"``.
    frames : (n, 3, 3) rotation matrices with columns ``(r, s, t)``; default
        ``spinal.frames(points)`` (double reflection).
    t0 : start time.
    reach : R > 0 (default ``radius``).
    falloff_power : p in {2, 3, 4} of the curl parts.
    blend : "c1" or "linear", the region function of ``tool="carry"``.
    """
    from ._frames import frames as _frames

    x = as_points(points, "points")
    f = _frames(x) if frames is None else as_float_array(frames, "frames")
    if f.shape != (len(x), 3, 3):
        raise ValueError(f"frames: expected shape {(len(x), 3, 3)}, got {f.shape}")
    return _core.field_path(x, np.ascontiguousarray(f), {
        "radius": as_real(radius, "radius"), "duration": as_real(duration, "duration"),
        "kind": kind, "tool": tool, "rate": as_finite(rate, "rate"), "t0": as_real(t0, "t0"),
        "reach": _opt(reach, "reach"), "falloff_power": _power(falloff_power), "blend": blend})


# ---- curl tools of any shape, keyframed tools ------------------------------------------------

def _motion(velocity, angular_velocity, pivot):
    return (None if velocity is None else as_vector(velocity, "velocity"),
            None if angular_velocity is None else as_vector(angular_velocity, "angular_velocity"),
            None if pivot is None else as_vector(pivot, "pivot"))


_CURL_DOC = """

    The curl fields of :func:`translation` and :func:`rotation` (thesis Ch. 12, corrected
    sign and scale) with the shape's signed distance ``d`` and its exact gradient
    ``g = ∇d`` in place of the sphere's (the construction of the free-form tools, thesis
    §11.2.5–11.2.6), ``e = R − |d|``, zero where ``|d| ≥ R``::

        translation  V = −(1/(2R^p)) curl(φ(d) (Y × u))
                       = (e^{p−1}/R^p) [ e u + (p/2) sgn(d) ((g·u) Y − (g·Y) u) ],  Y = X − C
        rotation     V = −(1/(3R^p)) curl(φ(d) B),  B = |Y|² Ω − (Ω·Y) Y,  Y = X − pivot
                       = (e^{p−1}/(3R^p)) [ p sgn(d) g × B + 3e Ω × Y ]

    with ``φ = (R − |d|)^p``. Both are curls of potentials, so ``div V = 0`` exactly for
    any C¹ ``d`` (interpolated or not); on the tool surface the normal velocity is the tool's
    rigid motion, ``u·n`` or ``(Ω × Y)·n``. Give exactly one of ``velocity`` (a translation,
    length/time) and ``angular_velocity`` (a rotation ``Ω``, rad/time, right-handed about
    ``Ω/|Ω|`` through ``pivot``, default the centre); add two fields for both (each then
    moves its own copy of the shape), or use :func:`keyframed` for a combined rigid motion.
    ``moving=True`` carries the shape with the motion (translated by ``u t``, or turned by
    ``|Ω| t`` about the pivot); ``moving=False`` keeps it where it is (a steady field).
    ``falloff_power`` ``p ∈ {2, 3, 4}`` (2: C⁰ at ``|d| = R``, 4: C²)."""


@_recorded
def sdf_curl(grid, origin, spacing, *, velocity=None, angular_velocity=None, pivot=None,
             center=None, reach=None, falloff_power: int = 2, moving: bool = True) -> Field:
    """A curl tool whose shape is a signed distance sampled on a grid (negative inside):
    ``d`` the C² tricubic B-spline interpolating the samples and ``g`` its exact gradient,
    as for :func:`sdf_tool` (whose arguments ``grid``, ``origin``, ``spacing``, ``center``
    and ``reach`` these are; the support ``|d| < reach``, inside the tool too, must stay
    inside the grid). RK4 is about 3rd order on it where path lines cross cell faces (see
    :func:`sdf_tool`)."""
    a, o, h = _sdf_samples(grid, origin, spacing)
    return _grid_curl(a, o, h, center, reach, velocity, angular_velocity, pivot, falloff_power,
                      moving, "sdf_curl")


def _grid_curl(values, origin, h, center, reach, velocity, angular_velocity, pivot,
               falloff_power, moving, name):
    u, w, p = _motion(velocity, angular_velocity, pivot)
    coef, c, reach = _grid_spline(values, origin, h, center, reach)
    return _core.field_grid_curl(coef, {"origin": origin, "spacing": h, "center": c,
                                        "reach": reach, "velocity": u, "angular_velocity": w,
                                        "pivot": p, "falloff_power": _power(falloff_power),
                                        "moving": as_bool(moving, "moving"), "name": name})


@_recorded
def mesh_curl(mesh, *, velocity=None, angular_velocity=None, pivot=None, reach=None,
              resolution: int = 64, center=None, falloff_power: int = 2,
              moving: bool = True, progress=False) -> Field:
    """A curl tool whose shape is a closed triangle mesh: its signed distance sampled on the
    grid of :func:`mesh_tool` (same ``mesh``, ``reach``, ``resolution``, ``center``,
    ``progress``; needs libigl), then :func:`sdf_curl`."""
    values, origin, h, c, rf = _mesh_samples(mesh, reach, resolution, center, progress)
    return _grid_curl(values, origin, h, c, rf, velocity, angular_velocity, pivot,
                      falloff_power, moving, "mesh_curl")


@_recorded
def rod(points, radius, *, velocity=None, angular_velocity=None, pivot=None, center=None,
        reach=None, falloff_power: int = 2, moving: bool = True) -> Field:
    """A curl tool whose shape is a rod: the tube of ``radius`` ρ about the axis through
    ``points`` (two points: a capsule).

    **Axis** as for :func:`strip_curve`: the clamped C² cubic spline ``γ`` through the points
    in chord length, with the end tangents of :func:`spinal.estimate_tangents`.
    **Distance** ``d = |X − γ(s*)| − ρ`` with ``s*`` the closest point of the axis (the end
    samples beyond the end planes: round caps), gradient ``g = (X − γ(s*))/|X − γ(s*)|``
    exactly (the envelope theorem); C¹ where the closest point is unique, which is checked
    for ``radius + reach`` (curvature and self-approach, ``ValueError`` naming ``points``).
    ``center`` C defaults to the centroid of the sample polyline, ``reach`` to ``radius``."""
    u, w, p = _motion(velocity, angular_velocity, pivot)
    c = None if center is None else as_vector(center, "center")
    return _core.field_rod(as_points(points, "points"), {
        "radius": as_real(radius, "radius"), "center": c, "reach": _opt(reach, "reach"),
        "velocity": u, "angular_velocity": w, "pivot": p, "falloff_power": _power(falloff_power),
        "moving": as_bool(moving, "moving")})


for _ctor in (sdf_curl, mesh_curl, rod):
    _ctor.__doc__ += _CURL_DOC
del _ctor


@_recorded
def keyframed(tool, times, positions, orientations=None, *,
              falloff_power: int | None = None, center=None) -> Field:
    """``tool`` following keyframed rigid poses ``(t_k, c_k, Q_k)``: the pose ``(c(t), Q(t))``
    takes the tool's point ``C`` to ``c(t)`` and turns it by ``Q(t)`` about it (``c_k = C``,
    ``Q_k = I`` leave it in place). Every field can be keyframed, in one of two ways.

    **A tool with a shape** (a field of one tool: :func:`translation`, :func:`rotation`,
    :func:`sphere` (its ball), :func:`capsule`, :func:`strip` (the rod of its two end points),
    :func:`strip_curve` (the rod about its axis, same spline), :func:`torus` (the torus'
    distance ``√((ρ − R_t)² + z²) − r_t``), :func:`sdf_curl`, :func:`mesh_curl`, :func:`rod`,
    :func:`sdf_tool`, :func:`mesh_tool` or a keyframed shape): the shape is moved, and the
    field is the curl tool of the moving shape. At time ``t`` the curl translation with
    ``u = ċ(t)`` and ``Y = X − c(t)`` plus, with ``orientations``, the curl rotation with
    ``Ω = ω(t)`` about ``c(t)`` (the formulas of :func:`sdf_curl`), with the shape's distance at
    the current pose, ``d(C + Qᵀ(X − c))`` (``d`` the distance of the shape as built), and its
    gradient turned back by ``Q``. On the tool surface the normal velocity is the rigid
    motion's, ``(ċ + ω × (X − c))·n``. Zero before the first and after the last key (the tool
    rests there). The shape is taken as the tool was built (where it is at ``t = 0``); ``C``
    defaults to the shape's centre
    ``C_s`` (a sphere's or torus' centre, a segment's midpoint, the centroid of a rod's or
    strip's sample polyline, a grid tool's ``center``), and a point on the shape is at
    ``c + Q (X_s − C)``. The reach is the tool's; ``falloff_power`` defaults to the tool's
    (2 for the cross-product tools sphere, capsule, strip, torus, strip_curve, sdf_tool,
    mesh_tool, whose blend the curl field does not use).

    **Any other field** (:func:`twist`, :func:`bend`, :func:`along_path`, a keyframed carried
    field, sums such as ``f + g`` or :func:`sum`): the whole field ``v₀`` is carried rigidly,

        v(X, t) = Q(t) v₀(C + Q(t)ᵀ(X − c(t)), t),

    the field seen in the moving frame of the pose. A rigid change of coordinates of a
    divergence-free field, so ``div v = 0`` (its Jacobian ``Q J₀ Qᵀ`` has ``J₀``'s trace); no
    rigid velocity ``ċ + ω × (X − c)`` is added (the field's action moves with the pose, the
    material is not dragged by it), and outside the keys the first or last pose is held (the
    field still acts there). ``center`` ``C`` defaults to the centre of a :func:`twist` or
    :func:`bend`; for sums, :func:`along_path` and carried fields it is required
    (``ValueError`` naming ``center``); ``falloff_power`` does not apply (``ValueError``).
    ``v₀`` keeps its own clock (it is evaluated at the same ``t``), so its breakpoints — an
    :func:`along_path`'s sample times, already counted from its ``t0`` — are not shifted:
    the field's :meth:`Field.breakpoints` are the key times together with ``v₀``'s. The
    default step count (:meth:`Field.steps`) uses ``max_speed`` = ``v₀``'s bound plus the
    speed of the pattern past the material, ``max|ċ| + max|ω| E`` with ``E`` the radius of
    ``v₀``'s support about ``C`` (twist, bend, along_path; ``max|ċ|`` alone for fields whose
    support moves without bound).

    **Interpolation.** Positions: cubic Hermite through the keys with Bessel tangents (the
    derivative of the parabola through three neighbouring keys, Catmull–Rom's for uniform
    times), so keys on a line at constant speed give exactly that motion; the velocity
    ``ċ`` (length/time) is continuous. Orientations: slerp along the shorter arc,
    ``Q = Q_k Exp(λ Log(Q_kᵀ Q_{k+1}))``, ``ω = Q_k Log(Q_kᵀ Q_{k+1})/Δt_k`` (rad/time)
    constant on each interval (it jumps at the keys). The key times are breakpoints, so
    :func:`spinal.advect` ends steps there and keeps RK4's order.

    For a shape orbiting a pivot this is a translation of the centre plus a spin about it:
    the same rigid motion (the same normal velocity on the tool) as :func:`rotation` about the
    pivot, with a different tangential flow.

    Parameters
    ----------
    tool : a Field (see above).
    times : (k,) key times, k ≥ 2, strictly increasing.
    positions : (k, 3) positions ``c_k`` of the point ``C``.
    orientations : (k, 3, 3) rotation matrices or (k, 4) unit quaternions ``(x, y, z, w)``
        (as :mod:`spinal.quaternions`); None: no turning (``Q = I``).
    falloff_power : p in {2, 3, 4}, default the tool's; only for a tool with a shape.
    center : (3,) the point ``C`` of the field taken to ``c_k``; default the shape's centre
        or the swirl's centre; required for sums and along_path.
    """
    if not isinstance(tool, Field):
        raise TypeError(f"tool: expected a spinal.fields.Field, got {type(tool).__name__}")
    t = as_float_array(times, "times")
    if t.ndim != 1:
        raise ValueError(f"times: expected a 1-D array, got shape {t.shape}")
    x = as_points(positions, "positions")
    mats = quats = None
    if orientations is not None:
        o = as_float_array(orientations, "orientations")
        if o.ndim == 3 and o.shape[1:] == (3, 3):
            mats = np.ascontiguousarray(o)
        elif o.ndim == 2 and o.shape[1] == 4:
            quats = np.ascontiguousarray(o)
        else:
            raise ValueError(f"orientations: expected shape (k, 3, 3) or (k, 4), got {o.shape}")
    p = None if falloff_power is None else _power(falloff_power)
    c = None if center is None else as_vector(center, "center")
    return _core.field_keyframed(tool, np.ascontiguousarray(t), x, mats, quats, p, c)
