"""spinal: moving frames, sweeps and volume-preserving deformations along 3D curves.

Frames are ``(n, 3, 3)`` rotation matrices whose columns are ``(r, s, t)``: the reference
vector, ``s = t × r`` and the unit tangent. See :func:`frames`. Sweeps and tubes turn
curves into watertight triangle meshes: :func:`sweep`, :func:`tube`, :class:`Mesh`.
:mod:`spinal.quaternions` holds frames as quaternion curves, cameras and a mesh walker.
The parallel calls use :func:`get_num_threads` worker threads (:func:`set_num_threads`,
:func:`threads`).
"""

from . import curves, fields, ph, quaternions
from ._advect import advect
from ._core import __version__
from ._deform import DeformReport, RefinementWarning, StampReport, deform, stamp
from ._flesh import SpineBinding, SurfaceBinding, flesh, flesh_surface
from ._frames import closing_angle, estimate_tangents, frames, frames_in_time
from ._mesh import FoldOverWarning, Mesh, SkippedCurvesWarning
from ._sweep import sweep, tube
from ._threads import get_num_threads, set_num_threads, threads

__all__ = [
    "DeformReport",
    "FoldOverWarning",
    "Mesh",
    "RefinementWarning",
    "SkippedCurvesWarning",
    "SpineBinding",
    "StampReport",
    "SurfaceBinding",
    "__version__",
    "advect",
    "closing_angle",
    "curves",
    "deform",
    "estimate_tangents",
    "fields",
    "flesh",
    "flesh_surface",
    "frames",
    "frames_in_time",
    "get_num_threads",
    "ph",
    "quaternions",
    "set_num_threads",
    "stamp",
    "sweep",
    "threads",
    "tube",
]
