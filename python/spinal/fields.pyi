from collections.abc import Callable, Iterable
from typing import Literal, TypeAlias

import numpy as np
import numpy.typing as npt

__all__ = [
    "Field",
    "along_path",
    "bend",
    "capsule",
    "keyframed",
    "mesh_curl",
    "mesh_tool",
    "rod",
    "rotation",
    "sdf_curl",
    "sdf_tool",
    "sphere",
    "strip",
    "strip_curve",
    "sum",
    "torus",
    "translation",
    "twist",
]

_Array: TypeAlias = npt.ArrayLike
_F: TypeAlias = npt.NDArray[np.float64]
_Power: TypeAlias = Literal[2, 3, 4]
_Blend: TypeAlias = Literal["c1", "linear"]
_Form: TypeAlias = Literal["rate", "curl"]

class Field:
    def __call__(self, points: _Array, t: float = 0.0) -> _F: ...
    def __add__(self, other: Field) -> Field: ...
    def __radd__(self, other: Literal[0]) -> Field: ...
    def __len__(self) -> int: ...
    def breakpoints(self) -> _F: ...
    @property
    def max_speed(self) -> float: ...
    @property
    def length_scale(self) -> float: ...
    def steps(self, duration: float, points: _Array | None = None, t0: float | None = None) -> int: ...

def translation(
    center: _Array,
    radius: float,
    velocity: _Array,
    *,
    reach: float | None = None,
    falloff_power: _Power = 2,
    moving: bool = True,
) -> Field: ...
def rotation(
    center: _Array,
    radius: float,
    axis: _Array,
    angular_speed: float,
    *,
    pivot: _Array | None = None,
    reach: float | None = None,
    falloff_power: _Power = 2,
) -> Field: ...
def twist(
    center: _Array, axis: _Array, rate: float, radius: float, *, form: _Form = "rate"
) -> Field: ...
def bend(
    center: _Array, axis: _Array, rate: float, radius: float, *, form: _Form = "rate"
) -> Field: ...
def sphere(
    center: _Array,
    radius: float,
    velocity: _Array,
    *,
    reach: float | None = None,
    blend: _Blend = "c1",
    moving: bool = True,
) -> Field: ...
def capsule(
    start: _Array,
    end: _Array,
    radius: float,
    velocity: _Array,
    *,
    reach: float | None = None,
    blend: _Blend = "c1",
    moving: bool = True,
) -> Field: ...
def strip(
    start: _Array,
    end: _Array,
    radius: float,
    velocity: _Array,
    *,
    kind: Literal["along", "across"] = "along",
    reach: float | None = None,
    blend: _Blend = "c1",
) -> Field: ...
def torus(
    center: _Array,
    axis: _Array,
    major: float,
    minor: float,
    speed: float,
    *,
    reach: float | None = None,
    blend: _Blend = "c1",
    moving: bool = True,
) -> Field: ...
def sum(fields: Iterable[Field]) -> Field: ...
def along_path(
    points: _Array,
    radius: float,
    duration: float,
    *,
    kind: Literal["translate", "rotate", "twist", "bend"] = "translate",
    tool: Literal["push", "carry"] = "push",
    rate: float = 0.0,
    frames: _Array | None = None,
    t0: float = 0.0,
    reach: float | None = None,
    falloff_power: _Power = 2,
    blend: _Blend = "c1",
) -> Field: ...

# private helpers shared with spinal's own modules (not API)
def _check_finite(x: npt.NDArray[np.float64], name: str) -> None: ...
def _real(x: object, name: str) -> float: ...
def _positive(x: object, name: str) -> float: ...
def _vec3(x: object, name: str) -> _F: ...
def strip_curve(
    points: _Array,
    radius: float,
    speed: float,
    *,
    reach: float | None = None,
    blend: _Blend = "c1",
) -> Field: ...
def sdf_tool(
    grid: _Array,
    origin: _Array,
    spacing: float,
    velocity: _Array,
    *,
    center: _Array | None = None,
    reach: float | None = None,
    blend: _Blend = "c1",
    moving: bool = True,
) -> Field: ...
def mesh_tool(
    mesh: object,
    velocity: _Array,
    *,
    reach: float | None = None,
    resolution: int = 64,
    center: _Array | None = None,
    blend: _Blend = "c1",
    moving: bool = True,
    progress: bool | Callable[[int, int], object] = False,
) -> Field: ...
def sdf_curl(
    grid: _Array,
    origin: _Array,
    spacing: float,
    *,
    velocity: _Array | None = None,
    angular_velocity: _Array | None = None,
    pivot: _Array | None = None,
    center: _Array | None = None,
    reach: float | None = None,
    falloff_power: _Power = 2,
    moving: bool = True,
) -> Field: ...
def mesh_curl(
    mesh: object,
    *,
    velocity: _Array | None = None,
    angular_velocity: _Array | None = None,
    pivot: _Array | None = None,
    reach: float | None = None,
    resolution: int = 64,
    center: _Array | None = None,
    falloff_power: _Power = 2,
    moving: bool = True,
    progress: bool | Callable[[int, int], object] = False,
) -> Field: ...
def rod(
    points: _Array,
    radius: float,
    *,
    velocity: _Array | None = None,
    angular_velocity: _Array | None = None,
    pivot: _Array | None = None,
    center: _Array | None = None,
    reach: float | None = None,
    falloff_power: _Power = 2,
    moving: bool = True,
) -> Field: ...
def keyframed(
    tool: Field,
    times: _Array,
    positions: _Array,
    orientations: _Array | None = None,
    *,
    falloff_power: _Power | None = None,
    center: _Array | None = None,
) -> Field: ...
