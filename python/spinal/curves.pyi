from typing import Literal, TypeAlias

import numpy as np
import numpy.typing as npt

__all__ = ["Bezier", "Curve", "Helix", "Polynomial", "Spline", "TorusKnot", "Viviani"]

_Array: TypeAlias = npt.ArrayLike
_F: TypeAlias = npt.NDArray[np.float64]
_U: TypeAlias = float | _Array

class Curve:
    domain: tuple[float, float]
    closed: bool
    def point(self, u: _U) -> _F: ...
    def d1(self, u: _U) -> _F: ...
    def d2(self, u: _U) -> _F: ...
    def d3(self, u: _U) -> _F: ...
    def parameters(self, n: int) -> _F: ...
    def sample(self, n: int) -> _F: ...
    def tangent(self, u: _U) -> _F: ...
    def curvature(self, u: _U) -> _F: ...
    def torsion(self, u: _U) -> _F: ...
    def speed(self, u: _U) -> _F: ...
    def frenet(self, u: _U) -> _F: ...

class Helix(Curve):
    a: float
    b: float
    def __init__(self, a: float = 1.0, b: float = 0.5, turns: float = 1.0) -> None: ...
    def rmf(self, u: _U, angle: float = 0.0) -> _F: ...

class TorusKnot(Curve):
    closed: bool
    p: int
    q: int
    R: float
    r: float
    def __init__(self, p: int = 2, q: int = 7, R: float = 0.6, r: float = 0.3) -> None: ...

class Viviani(Curve):
    closed: bool
    a: float
    def __init__(self, a: float = 1.0) -> None: ...

class Polynomial(Curve):
    coefficients: _F
    def __init__(
        self, coefficients: _Array, domain: tuple[float, float] = (0.0, 1.0)
    ) -> None: ...

class Bezier(Polynomial):
    control_points: _F
    def __init__(self, control_points: _Array) -> None: ...

class Spline(Curve):
    points: _F
    kind: Literal["catmull_rom", "natural_cubic", "bspline"]
    closed: bool
    knots: _F
    def __init__(
        self,
        points: _Array,
        kind: Literal["catmull_rom", "natural_cubic", "bspline"] = "catmull_rom",
        closed: bool = False,
    ) -> None: ...
    @property
    def length(self) -> float: ...
    def arc_length_parameters(self, n: int) -> _F: ...
    def sample_arc_length(self, n: int) -> _F: ...
