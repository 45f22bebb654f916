"""spinal: moving frames, sweeps and volume-preserving deformations along 3D curves.

NumPy arrays in, NumPy arrays out (float64; inputs never modified); the work is done by a
Rust core on all cores. Bad input raises ``ValueError``/``TypeError`` naming the argument.

Frames
    :func:`frames` (rotation-minimising by double reflection, rotation, projection, Frenet,
    RK4; closed curves, end conditions, bundles), :func:`closing_angle`,
    :func:`estimate_tangents`; analytic curves in :mod:`spinal.curves`.
Sweeps
    :func:`tube`, :func:`sweep` return a watertight :class:`Mesh` with normals and texture
    coordinates (``.save``, ``.to_trimesh``, ``.to_pyvista``, ``.plot``);
    :func:`profile_surface` (:class:`ProfileSurface`) analyses a profile sweep: normals,
    principal and Gaussian curvatures, parabolic lines, singular points, convexity.
Deformation
    Divergence-free velocity fields in :mod:`spinal.fields`; :func:`advect` (RK4, splitting),
    :func:`deform` (advection with refinement and a volume report, :class:`DeformReport`),
    :func:`stamp` (contact stamper, :class:`StampReport`), :func:`compensate_volume` (a
    target volume by one normal offset, :class:`CompensationReport`).
Fleshing
    :func:`flesh`, :class:`SpineBinding` (bending along a spine with local volume
    correction), :func:`flesh_surface`, :class:`SurfaceBinding` (spine surfaces).
Quaternion frames and PH cubics
    :mod:`spinal.quaternions` (conversions, slerp, transport, cameras, mesh walkers);
    :mod:`spinal.ph` (Pythagorean-hodograph cubics, G¹ PH splines, rational frames).

Threads
    The parallel calls use :func:`get_num_threads` worker threads (:func:`set_num_threads`,
    :func:`threads` for a block of code).

``python -m spinal demo`` runs a tour that writes its results to a folder.
"""

from . import curves, fields, io, ph, quaternions
from ._advect import advect
from ._compensate import CompensationReport, compensate_volume
from ._core import __version__
from ._deform import DeformReport, RefinementWarning, StampReport, deform, stamp
from ._flesh import SpineBinding, flesh
from ._flesh_surface import SurfaceBinding, flesh_surface
from ._frames import closing_angle, estimate_tangents, frames
from ._frames_time import frames_in_time
from ._mesh import FoldOverWarning, Mesh, PrecisionWarning, SkippedCurvesWarning
from ._profile import ProfileSurface, profile_surface
from ._sweep import sweep, tube
from ._threads import get_num_threads, set_num_threads, threads

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
