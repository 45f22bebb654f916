from typing import Any, Literal, TypeAlias, overload

import numpy as np
import numpy.typing as npt

from . import Mesh
from .curves import Curve

__all__ = [
    "PHSpline",
    "angle_fit",
    "evaluate",
    "fit",
    "from_quaternions",
    "hermite",
    "invariants",
    "is_ph",
    "preimage",
]

_Array: TypeAlias = npt.ArrayLike
_F: TypeAlias = npt.NDArray[np.float64]

@overload
def hermite(
    p0: _Array, t0: _Array, p1: _Array, t1: _Array, *, all: Literal[False] = False
) -> _F: ...
@overload
def hermite(
    p0: _Array, t0: _Array, p1: _Array, t1: _Array, *, all: Literal[True]
) -> _F | list[_F]: ...
@overload
def hermite(
    p0: _Array, t0: _Array, p1: _Array, t1: _Array, *, all: bool = False
) -> _F | list[_F]: ...
def is_ph(control_points: _Array, tol: float = 1e-9) -> bool | npt.NDArray[np.bool_]: ...
def from_quaternions(
    A0: _Array, A1: _Array, start: _Array = (0.0, 0.0, 0.0), *, scalar_first: bool = False
) -> _F: ...
def preimage(
    control_points: _Array, *, scalar_first: bool = False, tol: float = 1e-9
) -> tuple[_F, _F]: ...
def invariants(control_points: _Array) -> dict[str, Any]: ...
def evaluate(control_points: _Array, v: float | _Array, derivative: int = 0) -> _F: ...
def angle_fit(
    control_points: _Array, *, omega_start: float = 0.0, phi: float | None = None
) -> dict[str, Any]: ...
def fit(
    curve: Curve | _Array,
    *,
    tol: float | None = None,
    segments: int | None = None,
    knots: _Array | None = None,
    tangents: _Array | None = None,
    domain: tuple[float, float] | None = None,
    max_segments: int = 4096,
) -> PHSpline: ...

class PHSpline:
    deviation: _F | None
    def __init__(self, control_points: _Array, knots: _Array | None = None) -> None: ...
    @property
    def control_points(self) -> _F: ...
    @property
    def knots(self) -> _F: ...
    @property
    def segments(self) -> int: ...
    def __len__(self) -> int: ...
    def samples(self, n_per_segment: int = 16) -> _F: ...
    def parameter(self, u: float | _Array) -> _F: ...
    def evaluate(self, s: float | _Array, derivative: int = 0) -> _F: ...
    def points(self, n_per_segment: int = 16) -> _F: ...
    def frenet(self, s: float | _Array) -> _F: ...
    def rmf(
        self,
        s: float | _Array | None = None,
        *,
        initial: _Array | None = None,
        exact: bool = False,
        omega_start: float = 0.0,
        n_per_segment: int = 16,
    ) -> _F: ...
    def angle(
        self,
        s: float | _Array,
        *,
        initial: _Array | None = None,
        exact: bool = False,
        omega_start: float = 0.0,
    ) -> _F: ...
    def angle_fit(
        self, *, initial: _Array | None = None, omega_start: float = 0.0
    ) -> dict[str, Any]: ...
    def rational_frames(
        self, *, initial: _Array | None = None, omega_start: float = 0.0
    ) -> dict[str, _F]: ...
    def surface(
        self,
        section_ctrl: _Array,
        section_weights: _Array | None = None,
        *,
        initial: _Array | None = None,
        omega_start: float = 0.0,
    ) -> _F: ...
    def sweep(
        self,
        profile: _Array,
        *,
        n_per_segment: int = 16,
        initial: _Array | None = None,
        exact: bool = False,
        omega_start: float = 0.0,
        **kwargs: Any,
    ) -> Mesh: ...
