"""Type stubs for the compiled core (``spinal._core``). Use the wrappers in ``spinal``."""

from collections.abc import Callable, Sequence
from typing import TypeAlias

import numpy as np
import numpy.typing as npt

__version__: str

# The options of a call, one dict built by the Python wrapper (keys as in src/python/*.rs).
Options: TypeAlias = dict[str, object]
# frames_*: method, tangent_rule, tangent_chords, closed, initial_vectors, initial_frames,
# end_vectors, end_frames, turns, points_arg, and u, d1, d2, d3 for frames_steered
FrameOptions: TypeAlias = Options

def frames_sampled(
    points: npt.NDArray[np.float64] | None,
    tangents: npt.NDArray[np.float64] | None,
    offsets: npt.NDArray[np.int64],
    options: FrameOptions,
    progress: Callable[[int, int], object] | None = None,
    out: npt.NDArray[np.float64] | None = None,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def frames_analytic(
    points: npt.NDArray[np.float64],
    u: npt.NDArray[np.float64],
    d1: npt.NDArray[np.float64],
    d2: npt.NDArray[np.float64],
    options: FrameOptions,
    d3: npt.NDArray[np.float64] | None = None,
) -> tuple[npt.NDArray[np.float64], float]: ...
class RepeatedPointsError(ValueError): ...

def distinct_rows(
    points: npt.NDArray[np.float64],
    offsets: npt.NDArray[np.int64],
    closed: bool,
) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.uint8]]: ...
def estimate_tangents(
    points: npt.NDArray[np.float64],
    closed: bool,
    rule: str,
    offsets: npt.NDArray[np.int64] | None = None,
) -> npt.NDArray[np.float64]: ...
def frames_steered(
    points: npt.NDArray[np.float64] | None,
    tangents: npt.NDArray[np.float64] | None,
    offsets: npt.NDArray[np.int64],
    options: FrameOptions,
    steering: Options,
) -> npt.NDArray[np.float64]: ...
def frames_in_time(
    points: npt.NDArray[np.float64] | None,
    tangents: npt.NDArray[np.float64] | None,
    steps: int,
    options: FrameOptions,
    previous: npt.NDArray[np.float64] | None,
    progress: Callable[[int, int], object] | None = None,
) -> npt.NDArray[np.float64]: ...
def sweep_mesh(
    points: npt.NDArray[np.float64],
    frames: npt.NDArray[np.float64] | None,
    scale: npt.NDArray[np.float64],
    twist: npt.NDArray[np.float64] | None,
    offsets: npt.NDArray[np.int64],
    profile: npt.NDArray[np.float64],
    options: Options,
    progress: Callable[[int, int], object] | None = None,
) -> tuple[
    npt.NDArray[np.floating],
    npt.NDArray[np.signedinteger],
    npt.NDArray[np.floating] | None,
    npt.NDArray[np.floating] | None,
    npt.NDArray[np.int64],
    npt.NDArray[np.int64],
    npt.NDArray[np.int64],
]: ...
def quat_from_frames(frames: npt.NDArray[np.float64], continuous: bool) -> npt.NDArray[np.float64]: ...
def quat_to_frames(q: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
def quat_continuous(q: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
def quat_slerp(
    q0: npt.NDArray[np.float64], q1: npt.NDArray[np.float64], u: npt.NDArray[np.float64]
) -> npt.NDArray[np.float64]: ...
def quat_slerp_frames(
    frames: npt.NDArray[np.float64], key_u: npt.NDArray[np.float64], new_u: npt.NDArray[np.float64]
) -> npt.NDArray[np.float64]: ...
def camera_inputs(
    points: npt.NDArray[np.float64],
    tangents: npt.NDArray[np.float64] | None,
    up: npt.NDArray[np.float64] | None,
    bank: npt.NDArray[np.float64] | None,
    closed: bool,
    level: bool,
    singular_angle: float,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], bool, npt.NDArray[np.bool_] | None]: ...
def camera_level(
    tangents: npt.NDArray[np.float64], up: npt.NDArray[np.float64], regular: npt.NDArray[np.bool_]
) -> npt.NDArray[np.float64]: ...
def camera_orient(
    frames: npt.NDArray[np.float64], bank: npt.NDArray[np.float64] | None
) -> npt.NDArray[np.float64]: ...
def quat_spin(a: npt.NDArray[np.float64], b: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
def quat_path_length(q: npt.NDArray[np.float64], closed: bool) -> float: ...
def quat_transport(
    points: npt.NDArray[np.float64],
    tangents: npt.NDArray[np.float64] | None,
    initial: npt.NDArray[np.float64] | None,
    closed: bool,
    turns: float,
    closing_row: bool,
) -> tuple[npt.NDArray[np.float64], float]: ...
def walk_mesh_many(
    vertices: npt.NDArray[np.float64],
    faces: npt.NDArray[np.int64],
    face: npt.NDArray[np.int64],
    points: npt.NDArray[np.float64],
    directions: npt.NDArray[np.float64] | None,
    moves: npt.NDArray[np.float64],
    k: int,
) -> tuple[
    npt.NDArray[np.float64],
    npt.NDArray[np.int64],
    npt.NDArray[np.float64],
    npt.NDArray[np.bool_],
]: ...
def walk_mesh(
    vertices: npt.NDArray[np.float64],
    faces: npt.NDArray[np.int64],
    face: int,
    point: npt.NDArray[np.float64],
    direction: npt.NDArray[np.float64] | None,
    moves: npt.NDArray[np.float64],
) -> tuple[
    npt.NDArray[np.float64],
    npt.NDArray[np.int64],
    npt.NDArray[np.float64],
    npt.NDArray[np.bool_],
    npt.NDArray[np.float64],
    npt.NDArray[np.int64],
    npt.NDArray[np.int64],
]: ...

# PH cubics (spinal.ph). ph_hermite returns (candidates (m, 24): up to two cubics of 4
# control points per row, counts (m,), reason codes (m,)); ph_frame_setup returns one row of
# 34 floats per segment (src/ph/frame.rs, `Segment::to_row`).
def ph_hermite(
    p0: npt.NDArray[np.float64],
    t0: npt.NDArray[np.float64],
    p1: npt.NDArray[np.float64],
    t1: npt.NDArray[np.float64],
    all: bool,
    batch: bool,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int64], npt.NDArray[np.int64]]: ...
def ph_eval(
    control_points: npt.NDArray[np.float64], s: npt.NDArray[np.float64], derivative: int
) -> npt.NDArray[np.float64]: ...
def ph_invariants(control_points: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
def ph_is_ph(control_points: npt.NDArray[np.float64], tol: float) -> npt.NDArray[np.bool_]: ...
def ph_from_quaternions(
    a0: npt.NDArray[np.float64],
    a1: npt.NDArray[np.float64],
    start: npt.NDArray[np.float64],
    scalar_first: bool,
) -> npt.NDArray[np.float64]: ...
def ph_preimage(
    control_points: npt.NDArray[np.float64], tol: float, batch: bool, scalar_first: bool
) -> npt.NDArray[np.float64]: ...
def ph_check_spline(
    control_points: npt.NDArray[np.float64], knots: npt.NDArray[np.float64], single: bool
) -> None: ...
def ph_frame_setup(
    control_points: npt.NDArray[np.float64],
    initial: npt.NDArray[np.float64] | None,
    omega_start: float,
    phi: float | None,
) -> npt.NDArray[np.float64]: ...
def ph_frames(
    control_points: npt.NDArray[np.float64],
    s: npt.NDArray[np.float64],
    mode: str,
    initial: npt.NDArray[np.float64] | None,
    omega_start: float,
    phi: float | None,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
# Fields cross the binding as (k, 16) float64 rows, row[0] the element kind (layouts in
# src/deform/mod.rs, `Element::parse`): 0 curl translation, 1 curl rotation, 2 twist/bend,
# 3 sphere, 4 capsule, 5 torus, 6 strip across; multi-row elements are a header followed by
# its data rows: 7 path tool + n rows of kind 8, 9 strip along a curved axis + n rows of kind
# 10 (x, dγ/dS, S), 11 distance-grid tool + ⌈(nx+2)(ny+2)(nz+2)/15⌉ rows of kind 12 (B-spline
# coefficients). Build them with spinal.fields; the core re-validates every row.
_V3: TypeAlias = npt.NDArray[np.float64] | Sequence[float]

class Field:
    """A compiled divergence-free field (``spinal.fields.Field``)."""

    def __call__(self, points: npt.ArrayLike, t: float | None = None) -> npt.NDArray[np.float64]: ...
    def __add__(self, other: Field) -> Field: ...
    def __radd__(self, other: Field | int) -> Field: ...
    def __len__(self) -> int: ...
    def breakpoints(self) -> npt.NDArray[np.float64]: ...
    @property
    def max_speed(self) -> float: ...
    @property
    def length_scale(self) -> float: ...
    def steps(self, duration: float, points: npt.ArrayLike | None = None, t0: float | None = None) -> int: ...
    def __reduce__(self) -> tuple[object, tuple[list[object]]]: ...
    def _with_recipe(self, name: str, args: tuple[object, ...], kwargs: dict[str, object]) -> Field: ...

def field_translation(
    center: _V3, radius: float, velocity: _V3, reach: float | None, falloff_power: int, moving: bool
) -> Field: ...
def field_rotation(
    center: _V3,
    radius: float,
    axis: _V3,
    angular_speed: float,
    pivot: _V3 | None,
    reach: float | None,
    falloff_power: int,
) -> Field: ...
def field_swirl(center: _V3, axis: _V3, rate: float, radius: float, form: str, bend: bool) -> Field: ...
def field_sphere(
    center: _V3, radius: float, velocity: _V3, reach: float | None, blend: str, moving: bool
) -> Field: ...
def field_capsule(
    start: _V3,
    end: _V3,
    radius: float,
    velocity: _V3,
    reach: float | None,
    blend: str,
    moving: bool,
) -> Field: ...
def field_strip(
    start: _V3, end: _V3, radius: float, velocity: _V3, kind: str, reach: float | None, blend: str
) -> Field: ...
def field_torus(
    center: _V3,
    axis: _V3,
    major: float,
    minor: float,
    speed: float,
    reach: float | None,
    blend: str,
    moving: bool,
) -> Field: ...
def field_strip_curve(
    points: npt.NDArray[np.float64],
    radius: float,
    speed: float,
    reach: float | None,
    blend: str,
) -> Field: ...
def field_grid(
    coefficients: npt.NDArray[np.float64],
    options: Options,
) -> Field: ...
def field_grid_coefficients(values: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
def field_path(
    points: npt.NDArray[np.float64],
    frames: npt.NDArray[np.float64],
    options: Options,
) -> Field: ...
def field_zero() -> Field: ...
def field_grid_curl(
    coefficients: npt.NDArray[np.float64],
    options: Options,
) -> Field: ...
def field_rod(
    points: npt.NDArray[np.float64],
    options: Options,
) -> Field: ...
def field_keyframed(
    tool: Field,
    times: npt.NDArray[np.float64],
    positions: npt.NDArray[np.float64],
    matrices: npt.NDArray[np.float64] | None,
    quaternions: npt.NDArray[np.float64] | None,
    falloff_power: int | None,
    center: tuple[float, float, float] | npt.NDArray[np.float64] | None,
) -> Field: ...
def advect(
    points: npt.NDArray[np.float64],
    field: Field,
    t0: float,
    h: float,
    steps: int,
    method: str,
    out: npt.NDArray[np.float64] | None = None,
) -> npt.NDArray[np.float64]: ...
def advect_runs(
    points: npt.NDArray[np.float64],
    field: Field,
    runs: list[tuple[float, float, int]],
    method: str,
    progress: Callable[[int, int], object] | None = None,
    every: int = 0,
    out: npt.NDArray[np.float64] | None = None,
) -> npt.NDArray[np.float64]: ...
class DeformStats:
    """What ``deform_mesh`` did besides moving the vertices (frozen; pickles)."""

    def __init__(self, fields: dict[str, int | float | bool]) -> None: ...
    @property
    def passes(self) -> int: ...
    @property
    def torn(self) -> int: ...
    @property
    def over_threshold(self) -> int: ...
    @property
    def bounded(self) -> bool: ...
    @property
    def time_integrate(self) -> float: ...
    @property
    def time_refine(self) -> float: ...
    @property
    def slip_vertices(self) -> int: ...
    @property
    def fallback(self) -> int: ...
    @property
    def flips(self) -> int: ...
    @property
    def flip_volume(self) -> float: ...
    @property
    def collapses(self) -> int: ...
    @property
    def moves(self) -> int: ...
    @property
    def collapse_volume(self) -> float: ...
    @property
    def bent(self) -> int: ...
    @property
    def bend_splits(self) -> int: ...
    def _asdict(self) -> dict[str, int | float | bool]: ...
    def __reduce__(self) -> tuple[type[DeformStats], tuple[dict[str, int | float | bool]]]: ...

def deform_mesh(
    vertices: npt.NDArray[np.float64],
    faces: npt.NDArray[np.int64],
    field: Field,
    options: Options,
    progress: Callable[[int, int], object] | None = None,
) -> tuple[
    npt.NDArray[np.float64],
    npt.NDArray[np.float64],
    npt.NDArray[np.int64],
    npt.NDArray[np.int64],
    DeformStats,
]: ...
def mesh_volume(vertices: npt.NDArray[np.float64], faces: npt.NDArray[np.int64]) -> float: ...
def mesh_measure(
    vertices: npt.NDArray[np.float64] | npt.NDArray[np.float32],
    faces: npt.NDArray[np.int64] | npt.NDArray[np.int32],
    what: str,
) -> float: ...
def mesh_self_intersections(
    vertices: npt.NDArray[np.float64] | npt.NDArray[np.float32],
    faces: npt.NDArray[np.int64] | npt.NDArray[np.int32],
    limit: int,
) -> tuple[npt.NDArray[np.int64], bool]: ...
def mesh_edges(
    faces: npt.NDArray[np.int64] | npt.NDArray[np.int32], n: int
) -> tuple[int, int, int, int, int]: ...
def mesh_check_faces(faces: npt.NDArray[np.int64] | npt.NDArray[np.int32], n: int) -> None: ...
def mesh_check_finite(
    values: npt.NDArray[np.float64] | npt.NDArray[np.float32], arg: str
) -> None: ...
def mesh_closed_centroid(
    vertices: npt.NDArray[np.float64], faces: npt.NDArray[np.int64]
) -> tuple[float, list[float]]: ...
def minimal_rotation(
    t0: Sequence[float] | npt.NDArray[np.float64], t1: Sequence[float] | npt.NDArray[np.float64]
) -> npt.NDArray[np.float64]: ...
def flesh_bind(
    rest_points: npt.NDArray[np.float64],
    rest_frames: npt.NDArray[np.float64],
    vertices: npt.NDArray[np.float64],
    closed: bool = False,
) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.float64]]: ...
def flesh_deform(
    posed_points: npt.NDArray[np.float64],
    posed_frames: npt.NDArray[np.float64],
    edge: npt.NDArray[np.int64],
    coords: npt.NDArray[np.float64],
    options: Options,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.uint8]]: ...
def flesh_resample(
    posed_points: npt.NDArray[np.float64], chords: npt.NDArray[np.float64]
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def flesh_surface_bind(
    rest_points: npt.NDArray[np.float64], nu: int, nv: int, vertices: npt.NDArray[np.float64]
) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.float64], int]: ...
def flesh_trisurface_bind(
    rest_points: npt.NDArray[np.float64],
    faces: npt.NDArray[np.int64],
    vertices: npt.NDArray[np.float64],
) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.float64], int]: ...
def flesh_trisurface_frames(
    rest_points: npt.NDArray[np.float64], faces: npt.NDArray[np.int64]
) -> npt.NDArray[np.float64]: ...
def flesh_trisurface_deform(
    posed_points: npt.NDArray[np.float64],
    faces: npt.NDArray[np.int64],
    face: npt.NDArray[np.int64],
    coords: npt.NDArray[np.float64],
    options: Options,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.uint8]]: ...
def flesh_surface_deform(
    posed_points: npt.NDArray[np.float64],
    nu: int,
    nv: int,
    cell: npt.NDArray[np.int64],
    coords: npt.NDArray[np.float64],
    options: Options,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.uint8]]: ...
def stamp(
    vertices: npt.NDArray[np.float64],
    faces: npt.NDArray[np.int64],
    options: Options,
    progress: Callable[[int, int], object] | None = None,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...

# ---- worker threads (spinal._threads) ---------------------------------------------------------

def set_num_threads(n: int | None) -> None:
    """Set the thread count of the parallel calls (``None``: the default); ``1 <= n <= 1024``."""

def num_threads_setting() -> int | None:
    """The thread count set, or ``None`` for the default."""

def get_num_threads() -> int:
    """The thread count the next parallel call will use."""

def pool_threads() -> int:
    """``rayon::current_num_threads()`` seen from inside a heavy call (for the tests)."""
