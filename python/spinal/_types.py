"""Type aliases of the public signatures (for type checkers and readers of the annotations)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any, Literal, TypeAlias, Union

import numpy as np
import numpy.typing as npt

if TYPE_CHECKING:
    from ._mesh import Mesh

Array: TypeAlias = npt.ArrayLike
Float64Array: TypeAlias = npt.NDArray[np.float64]
Int64Array: TypeAlias = npt.NDArray[np.int64]
Ints: TypeAlias = Sequence[int] | npt.NDArray[np.integer]
# a bundle as users hold it: a list (any sequence, e.g. nibabel's ArraySequence) of (n_i, 3)
CurveBundle: TypeAlias = Sequence[Array] | Any
PointData: TypeAlias = dict[str, Array]
FrameMethod: TypeAlias = Literal["double_reflection", "projection", "rotation", "frenet",
                                  "rk4", "rk4_phi", "torsion", "bisector"]
Reflection: TypeAlias = Literal["chord", "tangents"]
Constraints: TypeAlias = dict[int, Array] | tuple[Array, Array]
TangentRule: TypeAlias = Literal["five_point_bounded", "five_point", "five_point_uniform",
                                  "circle"]
ProgressArg: TypeAlias = bool | Callable[[int, int], object]
AnyMesh: TypeAlias = Union["Mesh", Any, tuple[Array, Array]]  # Any: a trimesh.Trimesh
SpineSolution: TypeAlias = Literal["radial", "normal", "binormal", "blend", "none"]
SurfaceSolution: TypeAlias = Literal["offset", "none"]
Param: TypeAlias = float | Array
FalloffPower: TypeAlias = Literal[2, 3, 4]
Blend: TypeAlias = Literal["c1", "linear"]
Form: TypeAlias = Literal["rate", "curl"]
SplineKind: TypeAlias = Literal["catmull_rom", "natural_cubic", "bspline"]
