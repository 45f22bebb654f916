"""Type stubs for the compiled core (``spinal._core``). Use the wrappers in ``spinal``."""

import numpy as np
import numpy.typing as npt

__version__: str

def frames_sampled(
    points: npt.NDArray[np.float64] | None,
    tangents: npt.NDArray[np.float64] | None,
    offsets: npt.NDArray[np.int64],
    method: str,
    tangent_rule: str,
    tangent_chords: bool,
    closed: bool,
    initial_vectors: npt.NDArray[np.float64] | None,
    initial_frames: npt.NDArray[np.float64] | None,
    end_vectors: npt.NDArray[np.float64] | None,
    end_frames: npt.NDArray[np.float64] | None,
    turns: int,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def frames_analytic(
    points: npt.NDArray[np.float64],
    u: npt.NDArray[np.float64],
    d1: npt.NDArray[np.float64],
    d2: npt.NDArray[np.float64],
    method: str,
    closed: bool,
    initial_vectors: npt.NDArray[np.float64] | None,
    initial_frames: npt.NDArray[np.float64] | None,
    end_vectors: npt.NDArray[np.float64] | None,
    end_frames: npt.NDArray[np.float64] | None,
    turns: int,
) -> tuple[npt.NDArray[np.float64], float]: ...
def estimate_tangents(
    points: npt.NDArray[np.float64], closed: bool, rule: str
) -> npt.NDArray[np.float64]: ...
def sweep_mesh(
    points: npt.NDArray[np.float64],
    frames: npt.NDArray[np.float64],
    scale: npt.NDArray[np.float64],
    twist: npt.NDArray[np.float64] | None,
    offsets: npt.NDArray[np.int64],
    profile: npt.NDArray[np.float64],
    profile_closed: bool,
    closed: bool,
    caps: bool,
    miter_limit: float,
    split_seams: bool,
) -> tuple[
    npt.NDArray[np.float64],
    npt.NDArray[np.int64],
    npt.NDArray[np.float64],
    npt.NDArray[np.float64],
    npt.NDArray[np.int64],
]: ...
def field_eval(
    points: npt.NDArray[np.float64], rows: npt.NDArray[np.float64], t: float
) -> npt.NDArray[np.float64]: ...
def field_info(rows: npt.NDArray[np.float64], duration: float) -> tuple[float, float, int]: ...
def advect(
    points: npt.NDArray[np.float64],
    rows: npt.NDArray[np.float64],
    t0: float,
    h: float,
    steps: int,
    method: str,
) -> npt.NDArray[np.float64]: ...
