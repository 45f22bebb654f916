from collections.abc import Sequence
from typing import Literal, TypeAlias

import numpy as np
import numpy.typing as npt

from . import curves as curves
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
