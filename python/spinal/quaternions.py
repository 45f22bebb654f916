"""Quaternion frames (Hanson & Ma 1995; Ma 1996).

A frame ``F = (r, s, t)`` (columns, as everywhere in spinal) is the rotation ``R(q)`` of a
unit quaternion ``q``; ``q`` and ``−q`` give the same frame. Quaternion arrays are
``(n, 4)`` in scipy's order: ``(x, y, z, w)`` by default, ``(w, x, y, z)`` with
``scalar_first=True`` — exactly ``scipy.spatial.transform.Rotation.from_matrix(F)
.as_quat(scalar_first=...)`` up to sign, and ``Rotation.from_quat(q, scalar_first=...)
.as_matrix()`` returns the frames.

* :func:`to_quaternions` / :func:`from_quaternions` — conversions (Shepperd's method, robust
  at half turns), with sign continuity along a curve (:func:`make_continuous`).
* :func:`slerp`, :func:`slerp_frames` — interpolation of frames on the short great arc.
* :func:`quaternion_frames` — parallel transport as a quaternion recurrence
  ``Q_{i+1} = Δq_i Q_i``, ``Δq_i = normalise(1 + T_i·T_{i+1}, T_i × T_{i+1})``, with the
  closure correction of closed curves; or the Frenet frame as a quaternion curve.
* :func:`quaternion_length` — the length of the quaternion curve on S³, a measure of the
  frames' total turning (``½∫|ω| ds``: ``½∫κ ds`` for parallel transport,
  ``½∫√(κ²+τ²) ds`` for Frenet).
* :func:`spin` — the angle about the common tangent between two frames.
* :func:`camera_frames` — the frame a viewer flies with along a path, or a level-horizon
  camera with a fixed world up.
* :func:`walk_mesh` — a walker with a frame on a triangle mesh, rotated across every edge.
"""

from ._public import publish as _publish
from ._quaternions import (
    WalkResult,
    WalksResult,
    camera_frames,
    from_quaternions,
    make_continuous,
    quaternion_frames,
    quaternion_length,
    slerp,
    slerp_frames,
    spin,
    to_quaternions,
    walk_mesh,
    walk_mesh_many,
)

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

_publish(globals())  # documented, pickled and shown under this module's name
