import os
import pathlib
from collections.abc import Sequence
from typing import Any, Literal, TypeAlias

import numpy as np
import numpy.typing as npt

from . import curves as curves
from . import ph as ph
from . import quaternions as quaternions
from .curves import Curve

__version__: str

Method: TypeAlias = Literal["double_reflection", "projection", "rotation", "frenet", "rk4"]
_Array = npt.ArrayLike

def frames(
    points: _Array | Curve | None,
    tangents: _Array | None = None,
    *,
    method: Method = "double_reflection",
    initial: _Array | None = None,
    closed: bool = False,
    end: _Array | None = None,
    turns: int = 0,
    reflection: Literal["chord", "tangents"] = "chord",
    u: int | _Array | None = None,
    lengths: Sequence[int] | npt.NDArray[np.integer] | None = None,
    offsets: Sequence[int] | npt.NDArray[np.integer] | None = None,
) -> npt.NDArray[np.float64]: ...
def closing_angle(
    points: _Array | Curve | None,
    tangents: _Array | None = None,
    *,
    method: Method = "double_reflection",
    reflection: Literal["chord", "tangents"] = "chord",
    u: int | _Array | None = None,
    lengths: Sequence[int] | npt.NDArray[np.integer] | None = None,
    offsets: Sequence[int] | npt.NDArray[np.integer] | None = None,
) -> float | npt.NDArray[np.float64]: ...
def estimate_tangents(
    points: _Array, *, closed: bool = False, method: Literal["five_point", "five_point_uniform", "circle"] = "five_point"
) -> npt.NDArray[np.float64]: ...

_Ints: TypeAlias = Sequence[int] | npt.NDArray[np.integer]

class FoldOverWarning(UserWarning):
    indices: npt.NDArray[np.int64]
    def __init__(self, message: str, indices: npt.NDArray[np.int64]) -> None: ...

class Mesh:
    vertices: npt.NDArray[np.float64]
    faces: npt.NDArray[np.int64]
    normals: npt.NDArray[np.float64] | None
    uv: npt.NDArray[np.float64] | None
    fold_over: npt.NDArray[np.int64]
    def __init__(
        self,
        vertices: _Array,
        faces: _Array,
        normals: _Array | None = None,
        uv: _Array | None = None,
        fold_over: _Array | None = None,
    ) -> None: ...
    @property
    def volume(self) -> float: ...
    @property
    def area(self) -> float: ...
    @property
    def is_watertight(self) -> bool: ...
    def to_trimesh(self) -> Any: ...
    def to_pyvista(self) -> Any: ...
    def save(self, path: str | os.PathLike[str]) -> pathlib.Path: ...
    def plot(
        self, screenshot: str | os.PathLike[str] | None = None, *, window_size: tuple[int, int] = ..., **kwargs: Any
    ) -> npt.NDArray[np.uint8] | None: ...

def sweep(
    points: _Array,
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
) -> Mesh: ...
def tube(
    points: _Array,
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
) -> Mesh: ...

# ---- deformation (issue 4) ----
from collections.abc import Callable

from . import fields as fields
from .fields import Field

def advect(
    vertices: _Array,
    field: Field,
    duration: float,
    steps: int | None = None,
    *,
    method: Literal["rk4", "euler", "split"] = "rk4",
    t0: float = 0.0,
    progress: bool | Callable[[int, int], object] = False,
) -> npt.NDArray[np.float64]: ...

class DeformReport:
    rest_volume: float
    volume: float
    relative_change: float
    steps: int
    vertices_added: int
    passes: int
    integration_error: float | None
    mesh_error: float | None
    rest_vertices: npt.NDArray[np.float64] | None

def deform(
    mesh: Mesh | Any | tuple[_Array, _Array],
    field: Field,
    duration: float,
    steps: int | None = None,
    *,
    refine: float | None = 1.5,
    max_passes: int = 30,
    t0: float = 0.0,
    estimate: bool = False,
    progress: bool | Callable[[int, int], object] = False,
) -> tuple[Mesh, DeformReport]: ...

class SpineBinding:
    clamped: npt.NDArray[np.int64]
    def __init__(self, vertices: _Array, rest_spine: _Array) -> None: ...
    def __len__(self) -> int: ...
    @property
    def edge(self) -> npt.NDArray[np.int64]: ...
    @property
    def param(self) -> npt.NDArray[np.float64]: ...
    @property
    def arc_length(self) -> npt.NDArray[np.float64]: ...
    @property
    def offset(self) -> npt.NDArray[np.float64]: ...
    def posed_spine(self, posed_spine: _Array, *, stretchable: bool = False) -> npt.NDArray[np.float64]: ...
    def deform(
        self,
        posed_spine: _Array,
        *,
        solution: Literal["radial", "normal", "binormal", "none"] = "radial",
        stretchable: bool = False,
        twist: float | _Array | None = None,
        strict: bool = False,
        return_clamped: bool = False,
    ) -> Any: ...

def flesh(
    vertices: _Array,
    rest_spine: _Array,
    posed_spine: _Array,
    *,
    solution: Literal["radial", "normal", "binormal", "none"] = "radial",
    stretchable: bool = False,
    twist: float | _Array | None = None,
    strict: bool = False,
    return_clamped: bool = False,
) -> Any: ...

class SurfaceBinding:
    clamped: npt.NDArray[np.int64]
    def __init__(self, vertices: _Array, rest_surface: _Array) -> None: ...
    def __len__(self) -> int: ...
    @property
    def uv(self) -> npt.NDArray[np.float64]: ...
    @property
    def offset(self) -> npt.NDArray[np.float64]: ...
    def deform(
        self,
        posed_surface: _Array,
        *,
        solution: Literal["offset", "none"] = "offset",
        strict: bool = False,
        return_clamped: bool = False,
    ) -> Any: ...

def flesh_surface(
    vertices: _Array,
    rest_surface: _Array,
    posed_surface: _Array,
    *,
    solution: Literal["offset", "none"] = "offset",
    strict: bool = False,
    return_clamped: bool = False,
) -> Any: ...

class StampReport:
    rest_volume: float
    volume: float
    relative_change: float
    dent: npt.NDArray[np.float64]
    time: npt.NDArray[np.float64]
    residual: npt.NDArray[np.float64]
    contact: npt.NDArray[np.int64]

def stamp(
    mesh: Mesh | Any | tuple[_Array, _Array],
    start: _Array,
    end: _Array,
    radius: float,
    *,
    reach: float | None = None,
    frames: int = 10,
    iterations: int = 2,
) -> tuple[Mesh, StampReport]: ...
