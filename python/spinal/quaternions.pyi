from typing import Literal, NamedTuple, TypeAlias

import numpy as np
import numpy.typing as npt

__all__ = [
    "WalkResult",
    "WalksResult",
    "camera_frames",
    "from_quaternions",
    "make_continuous",
    "quaternion_frames",
    "quaternion_length",
    "slerp",
    "slerp_frames",
    "spin",
    "to_quaternions",
    "walk_mesh",
    "walk_mesh_many",
]

_Array: TypeAlias = npt.ArrayLike
_F: TypeAlias = npt.NDArray[np.float64]
_I: TypeAlias = npt.NDArray[np.int64]

def to_quaternions(
    frames: _Array, *, scalar_first: bool = False, continuous: bool = True
) -> _F: ...
def from_quaternions(quaternions: _Array, *, scalar_first: bool = False) -> _F: ...
def make_continuous(quaternions: _Array, *, scalar_first: bool = False) -> _F: ...
def slerp(q0: _Array, q1: _Array, u: float | _Array, *, scalar_first: bool = False) -> _F: ...
def slerp_frames(frames: _Array, new_u: _Array, key_u: _Array | None = None) -> _F: ...
def quaternion_frames(
    points: _Array,
    tangents: _Array | None = None,
    *,
    method: Literal["transport", "frenet"] = "transport",
    initial: _Array | None = None,
    closed: bool = False,
    turns: float = 0,
    scalar_first: bool = False,
) -> _F: ...
def quaternion_length(q: _Array, *, closed: bool = False, scalar_first: bool = False) -> float: ...
def spin(a: _Array, b: _Array) -> _F | float: ...
def camera_frames(
    points: _Array,
    *,
    up: _Array | None = None,
    mode: Literal["transport", "up"] = "transport",
    closed: bool = False,
    turns: int = 0,
    bank: float | _Array | None = None,
    tangents: _Array | None = None,
    singular_angle: float = 1e-3,
) -> _F: ...

class WalkResult(NamedTuple):
    points: _F
    faces: _I
    frames: _F
    stopped: npt.NDArray[np.bool_]
    path: _F
    path_faces: _I
    path_moves: _I

def walk_mesh(
    vertices: _Array,
    faces: _Array,
    face: int,
    point: _Array,
    moves: _Array,
    *,
    direction: _Array | None = None,
) -> WalkResult: ...

class WalksResult(NamedTuple):
    points: _F
    faces: _I
    frames: _F
    stopped: npt.NDArray[np.bool_]

def walk_mesh_many(
    vertices: _Array,
    faces: _Array,
    face: _Array,
    points: _Array,
    moves: _Array,
    *,
    directions: _Array | None = None,
) -> WalksResult: ...
