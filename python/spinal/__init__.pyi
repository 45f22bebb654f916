import os
import pathlib
from collections.abc import Callable, Sequence
from contextlib import AbstractContextManager
from dataclasses import dataclass
from typing import Any, Literal, TypeAlias, overload

import numpy as np
import numpy.typing as npt

from . import curves as curves
from . import fields as fields
from . import io as io
from . import ph as ph
from . import quaternions as quaternions
from .curves import Curve
from .fields import Field
from .ph import PHSpline

__all__ = [
    "CompensationReport",
    "DeformReport",
    "FoldOverWarning",
    "Mesh",
    "PrecisionWarning",
    "ProfileSurface",
    "RefinementWarning",
    "SkippedCurvesWarning",
    "SpineBinding",
    "StampReport",
    "SurfaceBinding",
    "__version__",
    "advect",
    "closing_angle",
    "compensate_volume",
    "curves",
    "deform",
    "estimate_tangents",
    "fields",
    "flesh",
    "flesh_surface",
    "frames",
    "frames_in_time",
    "get_num_threads",
    "io",
    "ph",
    "profile_surface",
    "quaternions",
    "set_num_threads",
    "stamp",
    "sweep",
    "threads",
    "tube",
]

__version__: str

_Array: TypeAlias = npt.ArrayLike
_F: TypeAlias = npt.NDArray[np.float64]
_I: TypeAlias = npt.NDArray[np.int64]
_Ints: TypeAlias = Sequence[int] | npt.NDArray[np.integer]
# a bundle as users hold it: a list (any sequence, e.g. nibabel's ArraySequence) of (n_i, 3)
_Curves: TypeAlias = Sequence[_Array] | Any
_PointData: TypeAlias = dict[str, _Array]
_Method: TypeAlias = Literal["double_reflection", "projection", "rotation", "frenet", "rk4", "rk4_phi",
                              "torsion", "bisector"]
_Reflection: TypeAlias = Literal["chord", "tangents"]
_Constraints: TypeAlias = dict[int, _Array] | tuple[_Array, _Array]
_TangentRule: TypeAlias = Literal["five_point_bounded", "five_point", "five_point_uniform", "circle"]
_Progress: TypeAlias = bool | Callable[[int, int], object]
_AnyMesh: TypeAlias = Mesh | Any | tuple[_Array, _Array]  # Any: a trimesh.Trimesh
_SpineSolution: TypeAlias = Literal["radial", "normal", "binormal", "blend", "none"]
_SurfaceSolution: TypeAlias = Literal["offset", "none"]

# ---- frames -------------------------------------------------------------------------------

def frames(
    points: _Array | Curve | _Curves | None,
    tangents: _Array | _Curves | None = None,
    *,
    method: _Method = "double_reflection",
    initial: _Array | None = None,
    closed: bool = False,
    end: _Array | None = None,
    turns: float = 0,
    reflection: _Reflection = "chord",
    u: int | _Array | None = None,
    lengths: _Ints | None = None,
    offsets: _Ints | None = None,
    constraints: _Constraints | Sequence[_Constraints | None] | None = None,
    twist_rule: Literal["arc_length", "min_angular_speed"] = "arc_length",
    guide: _Array | None = None,
    guide_weight: float = 1.0,
    guide_tolerance: float = 1e-3,
    previous: _Array | None = None,
    previous_twist: bool = False,
    previous_weight: float | None = None,
    guide_sign: Literal["follow", "free"] = "follow",
    on_invalid: Literal["raise", "skip"] = "raise",
    progress: _Progress = False,
    out: npt.NDArray[np.float64] | None = None,
) -> _F: ...
def frames_in_time(
    points_t: _Array | None,
    tangents_t: _Array | None = None,
    *,
    method: _Method = "double_reflection",
    initial: _Array | None = None,
    closed: bool = False,
    turns: float = 0,
    reflection: _Reflection = "chord",
    previous: _Array | None = None,
    previous_twist: bool = True,
    previous_weight: float | None = None,
    guide: _Array | None = None,
    guide_weight: float = 1.0,
    guide_tolerance: float = 1e-3,
    guide_sign: Literal["follow", "free"] = "follow",
    lengths: _Ints | None = None,
    offsets: _Ints | None = None,
    progress: _Progress = False,
) -> _F: ...
def closing_angle(
    points: _Array | Curve | _Curves | None,
    tangents: _Array | _Curves | None = None,
    *,
    method: _Method = "double_reflection",
    reflection: _Reflection = "chord",
    u: int | _Array | None = None,
    lengths: _Ints | None = None,
    offsets: _Ints | None = None,
) -> float | _F: ...
def estimate_tangents(
    points: _Array | _Curves,
    *,
    closed: bool = False,
    method: _TangentRule = "five_point_bounded",
    lengths: _Ints | None = None,
    offsets: _Ints | None = None,
    on_invalid: Literal["raise", "skip"] = "raise",
) -> _F: ...

# ---- meshes and sweeps --------------------------------------------------------------------

class FoldOverWarning(UserWarning):
    indices: _I
    curves: _I | None
    rows: _I | None
    def __init__(
        self, message: str, indices: _I, curves: _I | None = None, rows: _I | None = None
    ) -> None: ...

class SkippedCurvesWarning(UserWarning):
    curves: _I
    def __init__(self, message: str, curves: _I) -> None: ...

class PrecisionWarning(UserWarning):
    spacing: float
    feature: float
    def __init__(self, message: str, spacing: float, feature: float) -> None: ...

class Mesh:
    vertices: npt.NDArray[np.float64] | npt.NDArray[np.float32]
    faces: _I | npt.NDArray[np.int32]
    normals: _F | None
    uv: _F | None
    fold_over: _I
    point_data: dict[str, npt.NDArray[Any]]
    skipped_curves: _I
    def __init__(
        self,
        vertices: _Array,
        faces: _Array,
        normals: _Array | None = None,
        uv: _Array | None = None,
        fold_over: _Array | None = None,
        *,
        point_data: _PointData | None = None,
        cell_data: _PointData | None = None,
        sample_of: _Array | None = None,
        curve_of: _Array | None = None,
        skipped_curves: _Array | None = None,
    ) -> None: ...
    @property
    def cell_data(self) -> dict[str, npt.NDArray[Any]]: ...
    @property
    def sample_of(self) -> _I | None: ...
    @property
    def curve_of(self) -> _I | None: ...
    @property
    def volume(self) -> float: ...
    @property
    def area(self) -> float: ...
    def edge_stats(self) -> dict[str, int]: ...
    def self_intersections(self, limit: int = 10_000_000) -> npt.NDArray[np.int64]: ...
    @property
    def is_watertight(self) -> bool: ...
    @property
    def is_closed(self) -> bool: ...
    @property
    def is_winding_consistent(self) -> bool: ...
    @staticmethod
    def concatenate(meshes: Sequence[Mesh]) -> Mesh: ...
    def to_trimesh(self) -> Any: ...
    def to_pyvista(self) -> Any: ...
    def save(
        self, path: str | os.PathLike[str], *, colors: str | _Array | None = None
    ) -> pathlib.Path: ...
    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Mesh: ...
    def plot(
        self,
        screenshot: str | os.PathLike[str] | None = None,
        *,
        window_size: tuple[int, int] = (800, 600),
        **kwargs: Any,
    ) -> npt.NDArray[np.uint8] | None: ...

def sweep(
    points: _Array | _Curves,
    profile: _Array,
    *,
    frames: _Array | None = None,
    scale: float | _Array | None = None,
    twist: float | _Array | None = None,
    closed: bool = False,
    caps: bool = True,
    profile_closed: bool = True,
    miter_limit: float = 4.0,
    split_seams: bool = False,
    strict: bool = False,
    lengths: _Ints | None = None,
    offsets: _Ints | None = None,
    tangents: _Array | None = None,
    tangent_rule: _TangentRule = "five_point_bounded",
    dtype: npt.DTypeLike = "float64",
    normals: bool = True,
    uv: bool = True,
    point_data: _PointData | None = None,
    on_short: Literal["raise", "skip"] = "raise",
    on_invalid: Literal["raise", "skip"] = "raise",
    join: Literal["round", "bevel", "miter"] = "round",
    progress: _Progress = False,
    turns: float = 0,
    out: Mesh | None = None,
) -> Mesh: ...
def tube(
    points: _Array | _Curves,
    radius: float | _Array = 1.0,
    sides: int = 16,
    *,
    frames: _Array | None = None,
    closed: bool = False,
    caps: bool = True,
    miter_limit: float = 4.0,
    split_seams: bool = False,
    strict: bool = False,
    lengths: _Ints | None = None,
    offsets: _Ints | None = None,
    tangents: _Array | None = None,
    tangent_rule: _TangentRule = "five_point_bounded",
    dtype: npt.DTypeLike = "float64",
    normals: bool = True,
    uv: bool = True,
    point_data: _PointData | None = None,
    on_short: Literal["raise", "skip"] = "raise",
    on_invalid: Literal["raise", "skip"] = "raise",
    join: Literal["round", "bevel", "miter"] = "round",
    progress: _Progress = False,
    turns: float = 0,
    out: Mesh | None = None,
) -> Mesh: ...

# ---- profile (moulding) surfaces -----------------------------------------------------------

@dataclass(frozen=True, eq=False)
class ProfileSurface:
    u: _F
    v: _F
    points: _F
    normals: _F
    frames: _F
    spine_curvature: _F
    profile_tangents: _F
    profile_curvature: _F
    mu: _F
    curvature_u: _F
    curvature_v: _F
    k1: _F
    k2: _F
    d1: _F
    d2: _F
    gaussian: _F
    mean: _F
    parabolic_sign: npt.NDArray[np.int8]
    singular_points: _F
    singularity_free: bool
    convex: bool
    profile_turning: float
    frame_turning: float
    convexity_criterion: bool
    convex_turns: _F | None
    closed: bool
    profile_closed: bool
    def parabolic_lines(self, space: Literal["parameters", "points"] = "parameters") -> list[_F]: ...
    def mesh(self) -> Mesh: ...

def profile_surface(
    spine: _Array | Curve | PHSpline,
    profile: _Array | Curve,
    u: int | _Array | None = None,
    v: int | _Array | None = None,
    *,
    frames: _Array | None = None,
    initial: _Array | None = None,
    closed: bool = False,
    profile_closed: bool = False,
) -> ProfileSurface: ...

# ---- deformation by divergence-free fields ------------------------------------------------

def advect(
    vertices: _Array,
    field: Field,
    duration: float,
    steps: int | None = None,
    *,
    method: Literal["rk4", "euler", "split"] = "rk4",
    t0: float = 0.0,
    progress: _Progress = False,
    out: npt.NDArray[np.float64] | None = None,
) -> _F: ...
@dataclass(frozen=True)
class DeformReport:
    rest_volume: float
    volume: float
    relative_change: float
    steps: int
    vertices_added: int
    passes: int
    integration_error: float | None = None
    mesh_error: float | None = None
    rest_vertices: _F | None = None
    converged: bool = True
    edges_over_threshold: int = 0
    max_vertices: int | None = None
    torn_vertices: int = 0
    step_vertices: _I | None = None
    timings: dict[str, float] | None = None
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

class RefinementWarning(UserWarning): ...

def deform(
    mesh: _AnyMesh,
    field: Field,
    duration: float,
    steps: int | None = None,
    *,
    refine: float | None = 1.5,
    max_passes: int = 30,
    t0: float = 0.0,
    estimate: bool = False,
    progress: _Progress = False,
    max_vertices: int | None = None,
    check: bool | Literal["intersections"] = True,
) -> tuple[Mesh, DeformReport]: ...
@dataclass(frozen=True)
class StampReport:
    rest_volume: float
    volume: float
    relative_change: float
    dent: _F
    time: _F
    residual: _F
    contact: _I

def stamp(
    mesh: _AnyMesh,
    start: _Array,
    end: _Array,
    radius: float,
    *,
    reach: float | None = None,
    frames: int = 10,
    iterations: int = 2,
    progress: _Progress = False,
) -> tuple[Mesh, StampReport]: ...
@dataclass(frozen=True)
class CompensationReport:
    offset: float
    volume_before: float
    volume_after: float
    target: float
    steiner_offset: float
    iterations: int

def compensate_volume(mesh: _AnyMesh, target: float) -> tuple[Mesh, CompensationReport]: ...

# ---- fleshing -----------------------------------------------------------------------------

class SpineBinding:
    clamped: _I
    def __init__(self, vertices: _Array, rest_spine: _Array, *, closed: bool = False) -> None: ...
    def __len__(self) -> int: ...
    @property
    def edge(self) -> _I: ...
    @property
    def rest_frames(self) -> _F: ...
    @property
    def param(self) -> _F: ...
    @property
    def arc_length(self) -> _F: ...
    @property
    def offset(self) -> _F: ...
    def posed_spine(self, posed_spine: _Array, *, stretchable: bool = False) -> _F: ...
    @overload
    def deform(
        self,
        posed_spine: _Array,
        *,
        solution: _SpineSolution = "radial",
        blend: float | None = None,
        stretchable: bool = False,
        twist: float | _Array | None = None,
        strict: bool = False,
        return_clamped: Literal[False] = False,
        posed_frames: _Array | None = None,
        posed_up: _Array | None = None,
        slide: float = 0.0,
    ) -> _F: ...
    @overload
    def deform(
        self,
        posed_spine: _Array,
        *,
        solution: _SpineSolution = "radial",
        blend: float | None = None,
        stretchable: bool = False,
        twist: float | _Array | None = None,
        strict: bool = False,
        return_clamped: Literal[True],
        posed_frames: _Array | None = None,
        posed_up: _Array | None = None,
        slide: float = 0.0,
    ) -> tuple[_F, _I]: ...
    @overload
    def deform(
        self,
        posed_spine: _Array,
        *,
        solution: _SpineSolution = "radial",
        blend: float | None = None,
        stretchable: bool = False,
        twist: float | _Array | None = None,
        strict: bool = False,
        return_clamped: bool = False,
        posed_frames: _Array | None = None,
        posed_up: _Array | None = None,
        slide: float = 0.0,
    ) -> _F | tuple[_F, _I]: ...
    def animate(
        self,
        posed_spines_t: _Array,
        *,
        solution: _SpineSolution = "radial",
        blend: float | None = None,
        stretchable: bool = False,
        twist: float | _Array | None = None,
        slide: float | _Array = 0.0,
        previous_weight: float = 1000.0,
        progress: _Progress = False,
    ) -> _F: ...

@overload
def flesh(
    vertices: _Array,
    rest_spine: _Array,
    posed_spine: _Array,
    *,
    solution: _SpineSolution = "radial",
    blend: float | None = None,
    stretchable: bool = False,
    twist: float | _Array | None = None,
    strict: bool = False,
    return_clamped: Literal[False] = False,
    closed: bool = False,
    posed_frames: _Array | None = None,
    posed_up: _Array | None = None,
) -> _F: ...
@overload
def flesh(
    vertices: _Array,
    rest_spine: _Array,
    posed_spine: _Array,
    *,
    solution: _SpineSolution = "radial",
    blend: float | None = None,
    stretchable: bool = False,
    twist: float | _Array | None = None,
    strict: bool = False,
    return_clamped: Literal[True],
    closed: bool = False,
    posed_frames: _Array | None = None,
    posed_up: _Array | None = None,
) -> tuple[_F, _I]: ...
@overload
def flesh(
    vertices: _Array,
    rest_spine: _Array,
    posed_spine: _Array,
    *,
    solution: _SpineSolution = "radial",
    blend: float | None = None,
    stretchable: bool = False,
    twist: float | _Array | None = None,
    strict: bool = False,
    return_clamped: bool = False,
    closed: bool = False,
    posed_frames: _Array | None = None,
    posed_up: _Array | None = None,
) -> _F | tuple[_F, _I]: ...

class SurfaceBinding:
    clamped: _I
    def __init__(
        self, vertices: _Array, rest_surface: _Array | Mesh | tuple[_Array, _Array]
    ) -> None: ...
    def __len__(self) -> int: ...
    @property
    def face(self) -> _I: ...
    @property
    def barycentric(self) -> _F: ...
    @property
    def uv(self) -> _F: ...
    @property
    def offset(self) -> _F: ...
    @property
    def rest_frames(self) -> _F: ...
    @overload
    def deform(
        self,
        posed_surface: _Array,
        *,
        solution: _SurfaceSolution = "offset",
        strict: bool = False,
        return_clamped: Literal[False] = False,
        posed_frames: _Array | None = None,
        posed_up: _Array | None = None,
    ) -> _F: ...
    @overload
    def deform(
        self,
        posed_surface: _Array,
        *,
        solution: _SurfaceSolution = "offset",
        strict: bool = False,
        return_clamped: Literal[True],
        posed_frames: _Array | None = None,
        posed_up: _Array | None = None,
    ) -> tuple[_F, _I]: ...
    @overload
    def deform(
        self,
        posed_surface: _Array,
        *,
        solution: _SurfaceSolution = "offset",
        strict: bool = False,
        return_clamped: bool = False,
        posed_frames: _Array | None = None,
        posed_up: _Array | None = None,
    ) -> _F | tuple[_F, _I]: ...

@overload
def flesh_surface(
    vertices: _Array,
    rest_surface: _Array | Mesh | tuple[_Array, _Array],
    posed_surface: _Array,
    *,
    solution: _SurfaceSolution = "offset",
    strict: bool = False,
    return_clamped: Literal[False] = False,
    posed_frames: _Array | None = None,
    posed_up: _Array | None = None,
) -> _F: ...
@overload
def flesh_surface(
    vertices: _Array,
    rest_surface: _Array | Mesh | tuple[_Array, _Array],
    posed_surface: _Array,
    *,
    solution: _SurfaceSolution = "offset",
    strict: bool = False,
    return_clamped: Literal[True],
    posed_frames: _Array | None = None,
    posed_up: _Array | None = None,
) -> tuple[_F, _I]: ...
@overload
def flesh_surface(
    vertices: _Array,
    rest_surface: _Array | Mesh | tuple[_Array, _Array],
    posed_surface: _Array,
    *,
    solution: _SurfaceSolution = "offset",
    strict: bool = False,
    return_clamped: bool = False,
    posed_frames: _Array | None = None,
    posed_up: _Array | None = None,
) -> _F | tuple[_F, _I]: ...

# ---- worker threads -----------------------------------------------------------------------

def set_num_threads(n: int | None) -> None: ...
def get_num_threads() -> int: ...
def threads(n: int | None) -> AbstractContextManager[None]: ...
