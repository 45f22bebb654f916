r"""``spinal.compensate_volume``: give a closed mesh a target volume by moving every vertex one
constant distance along its normal (Zhuo 2014, §2.2.2 and ch. IX: global volume
compensation after a deformation).

The maths, in the mesh's length unit L (volumes in L³, areas in L²):

* **Steiner's formula** (Steiner 1840; Schneider, *Convex Bodies: The Brunn–Minkowski
  Theory*, §4.2). The parallel surface at distance ``h`` of a smooth closed surface encloses

      V(h) = V + A h + M h² + (G/3) h³,

  ``A`` the area, ``M = ∫ H dA`` the total mean curvature (``H = (κ₁ + κ₂)/2``, positive on
  a sphere with outward normals) and ``G = ∫ K dA = 2πχ`` the total Gaussian curvature
  (Gauss–Bonnet, ``χ = V − E + F``). A sphere of radius R has ``A = 4πR²``, ``M = 4πR``,
  ``G/3 = 4π/3``, and ``V(h) = (4π/3)(R + h)³`` exactly. (Written as ``(4π/3) χ h³`` the cubic
  term would be twice too large: 8π/3 h³ on a sphere.)
* **Polytopes.** For a triangle mesh ``M = ½ Σ_edges |e| θ_e``, ``θ_e`` the signed exterior
  dihedral angle at ``e`` (the angle between the two face normals, positive where the
  surface is convex); the cubic term keeps ``G = 2πχ`` (the sum of the angle defects, discrete
  Gauss–Bonnet). For a convex polyhedron ``V(h)`` is then the exact volume of its outer
  parallel body (Schneider §4.2, the quermassintegrals of a polytope); on fine meshes of
  smooth surfaces ``M`` converges to ``∫ H dA`` (the edge-based mean curvature of Meyer,
  Desbrun, Schröder & Barr, "Discrete differential-geometry operators for triangulated
  2-manifolds", VisMath 2002/2003, §3.5).
* **The mesh's own volume.** Moving vertex ``i`` to ``x_i + h n_i`` (``n_i`` the area-weighted
  unit vertex normal) is not the parallel surface, but its enclosed volume
  ``V_mesh(h) = ⅙ Σ_f x_a·(x_b × x_c)`` is again a cubic in ``h`` with slope

      dV_mesh/dh = Σ_i n_i · ∂V/∂x_i = ⅙ Σ_f N_f · (n_a + n_b + n_c),

  ``∂V/∂x_i = ⅓ Σ_{f ∋ i} A_f n̂_f`` and ``N_f = (x_b − x_a) × (x_c − x_a)`` (twice the face
  area times its unit normal). Newton steps on it, from Steiner's ``h``, reach the target.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import overload

import numpy as np

from . import _core
from ._mesh import Mesh, mesh_arrays, signed_volume
from ._types import AnyMesh
from ._validate import as_positive

__all__ = ["CompensationReport", "compensate_volume"]

#: Newton steps on the mesh's own volume after Steiner's offset (each at least doubles the
#: correct digits of an exact cubic; 2–4 are taken in practice).
MAX_POLISH = 8
#: The volume is reached when ``|V(h) − target| ≤ RTOL · target``.
RTOL = 1e-12
#: Steps of the safeguarded Newton iteration on Steiner's cubic (bisection alone would halve a
#: bracket as wide as float64's range down to one ulp in fewer).
MAX_STEINER = 2200


@dataclass(frozen=True)
class CompensationReport:
    """What :func:`compensate_volume` did. Lengths in the mesh's units, volumes in those
    units cubed (signed: outward-wound meshes are positive).

    Attributes
    ----------
    offset : float
        The distance ``h`` every vertex moved along its unit normal (``> 0`` outwards).
    volume_before, volume_after : float
        Enclosed volume of the input mesh and of the returned one.
    target : float
        The volume asked for (``|volume_after − target| ≤ 1e-12 · target`` unless the
        floating-point rounding of the vertices stops the iteration short of it).
    steiner_offset : float
        The root of Steiner's cubic ``V + A h + M h² + (2πχ/3) h³ = target`` nearest 0, the
        start of the Newton steps (``offset − steiner_offset`` measures how far the vertex-
        normal offset of the mesh is from its parallel surface).
    iterations : int
        Newton steps taken on the mesh's own volume after Steiner's offset.
    """

    offset: float
    volume_before: float
    volume_after: float
    target: float
    steiner_offset: float
    iterations: int


# ---- the mesh's quantities -----------------------------------------------------------------


def face_normals(X: np.ndarray, F: np.ndarray) -> np.ndarray:
    """``N_f = (x_b − x_a) × (x_c − x_a)``, ``(F, 3)``: twice the face area times its unit
    normal (outwards on an outward-wound mesh)."""
    a, b, c = X[F[:, 0]], X[F[:, 1]], X[F[:, 2]]
    return np.cross(b - a, c - a)


def vertex_normals(X: np.ndarray, F: np.ndarray, N: np.ndarray) -> np.ndarray:
    """Area-weighted unit vertex normals ``n_i = Σ_{f∋i} N_f / |Σ_{f∋i} N_f|``, ``(V, 3)``;
    zero on a vertex in no face (or whose faces' normals cancel): it does not move."""
    corners = F.ravel()
    s = np.stack([np.bincount(corners, np.repeat(N[:, k], 3), len(X)) for k in range(3)], 1)
    length = np.linalg.norm(s, axis=1)
    out = np.zeros_like(s)
    ok = length > 0
    out[ok] = s[ok] / length[ok, None]
    return out


def _edge_pairs(F: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For each undirected edge of a closed, consistently wound mesh: ``(a, b, f1, f2)`` as
    three arrays — its ends ``(E, 2)`` in the direction face ``f1`` runs them (``a → b``;
    ``f2`` runs ``b → a``), ``f1`` and ``f2``."""
    directed = F[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
    face = np.repeat(np.arange(len(F)), 3)
    n = int(F.max()) + 1 if len(F) else 0
    lo, hi = directed.min(axis=1), directed.max(axis=1)
    order = np.lexsort((directed[:, 0] > directed[:, 1], lo * n + hi))
    # each edge twice (the mesh is closed): first the slot running low → high
    first, second = order[0::2], order[1::2]
    return directed[first], face[first], face[second]


def total_mean_curvature(X: np.ndarray, F: np.ndarray, N: np.ndarray | None = None) -> float:
    """``M = ½ Σ_edges |e| θ_e`` of a closed, outward-wound mesh: ``θ_e`` the signed exterior
    dihedral angle, ``atan2((N₁ × N₂)·ê, N₁·N₂)`` with ``ê`` the edge's direction in face 1
    (positive where convex). Exact Steiner coefficient of a convex polyhedron (Schneider
    §4.2); ``≈ ∫ H dA`` on fine meshes of smooth surfaces (Meyer et al. 2003)."""
    if N is None:
        N = face_normals(X, F)
    ends, f1, f2 = _edge_pairs(F)
    e = X[ends[:, 1]] - X[ends[:, 0]]
    length = np.linalg.norm(e, axis=1)
    n1, n2 = N[f1], N[f2]
    sine = np.einsum("ij,ij->i", np.cross(n1, n2), e)  # |N₁||N₂| sin θ · |e|
    cosine = np.einsum("ij,ij->i", n1, n2) * length  # |N₁||N₂| cos θ · |e|
    theta = np.arctan2(sine, cosine)
    return float(0.5 * np.dot(length, theta))


def euler_characteristic(F: np.ndarray) -> int:
    """``χ = V − E + F`` of a closed mesh (its vertices: those in a face; ``E = 3F/2``)."""
    return len(np.unique(F)) - 3 * len(F) // 2 + len(F)


def steiner_coefficients(X: np.ndarray, F: np.ndarray) -> tuple[float, float, float, float]:
    """``(V, A, M, G/3)``: the coefficients of Steiner's cubic
    ``V(h) = V + A h + M h² + (G/3) h³`` of a closed, outward-wound mesh, with
    ``G/3 = 2πχ/3`` (not ``(4π/3) χ``, twice too large)."""
    N = face_normals(X, F)
    area = 0.5 * float(np.linalg.norm(N, axis=1).sum())
    return (signed_volume(X, F), area, total_mean_curvature(X, F, N),
            2 * np.pi * euler_characteristic(F) / 3)


# ---- Steiner's offset ----------------------------------------------------------------------


@overload
def _unscaled(x: float, e: int) -> float: ...
@overload
def _unscaled(x: np.ndarray, e: int) -> np.ndarray: ...
def _unscaled(x: float | np.ndarray, e: int) -> float | np.ndarray:
    """``x · 2**e`` (a length with ``e``, a volume with ``3e``), ``±inf`` past float64."""
    with np.errstate(over="ignore", under="ignore"):
        y = np.ldexp(x, e)
    return float(y) if np.ndim(y) == 0 else y


def _too_large(volume: float, target: float, why: str) -> ValueError:
    return ValueError(f"target: the change from volume {volume:.6g} to {target:.6g} is too "
                      f"large for a normal offset ({why})")


def _increasing_branch(A: float, M: float, C: float) -> tuple[float, float]:
    """``(lo, hi)``, ``lo < 0 < hi`` (may be infinite): the interval around 0 on which
    ``V'(h) = A + 2M h + 3C h² > 0`` (``V'(0) = A > 0``)."""
    if C == 0:
        roots = [-A / (2 * M)] if M != 0 else []
    else:
        disc = M * M - 3 * A * C
        if disc < 0:
            roots = []
        else:  # the stable pair of roots of 3C h² + 2M h + A
            q = -(M + np.copysign(np.sqrt(disc), M))
            roots = [q / (3 * C), A / q] if q != 0 else []
    lo = max((r for r in roots if r < 0), default=-np.inf)
    hi = min((r for r in roots if r > 0), default=np.inf)
    return lo, hi


def steiner_offset(coefficients: tuple[float, float, float, float], target: float,
                   e: int = 0) -> float:
    """The root ``h`` of ``V + A h + M h² + C h³ = target`` on the branch through ``h = 0``
    where the volume grows with ``h`` (the root nearest 0 reached without passing a fold of
    the parallel surface): safeguarded Newton on a bracket, from that root of the companion
    matrix's eigenvalues (``numpy.roots``) or else ``h₀ = (target − V)/A``. ``ValueError``
    naming ``target`` when the branch does not reach the target (its message in the units of
    the mesh scaled by ``2**e``)."""
    V, A, M, C = coefficients

    def p(h: float) -> float:  # V(h) − target, Horner
        return (V - target) + h * (A + h * (M + h * C))

    def dp(h: float) -> float:
        return A + h * (2 * M + 3 * h * C)

    lo, hi = _increasing_branch(A, M, C)
    if target == V:
        return 0.0
    if target > V:
        lo = 0.0
        if not np.isfinite(hi):
            hi = _bracket(p, (target - V) / A)
    else:
        hi = 0.0
        if not np.isfinite(lo):
            lo = _bracket(p, (target - V) / A)
    if not p(lo) <= 0 <= p(hi):
        edge = hi if target > V else lo
        raise _too_large(_unscaled(V, 3 * e), _unscaled(target, 3 * e),
                         f"the parallel surface's volume turns back at offset "
                         f"{_unscaled(edge, e):.4g}, at volume "
                         f"{_unscaled(p(edge) + target, 3 * e):.6g}")
    return _newton_on_bracket(p, dp, lo, hi, _start(coefficients, target, lo, hi))


def _start(coefficients: tuple[float, float, float, float], target: float, lo: float,
           hi: float) -> float:
    """A real root of the cubic in ``[lo, hi]`` from ``numpy.roots`` (eigenvalues of the
    companion matrix), else ``(target − V)/A``."""
    V, A, M, C = coefficients
    roots = np.roots([C, M, A, V - target])
    real = roots.real[np.abs(roots.imag) <= 1e-8 * np.abs(roots)]
    real = real[(real >= lo) & (real <= hi)]
    return float(real[np.argmin(np.abs(real))]) if len(real) else (target - V) / A


def _bracket(p: Callable[[float], float], step: float) -> float:
    """An end ``h`` (same sign as ``step``) with ``p(h)`` of the other sign than ``p(0)``, by
    doubling ``step`` (``p`` monotone and unbounded that way)."""
    h = step
    for _ in range(2100):
        if np.sign(p(h)) != np.sign(p(0.0)):
            return h
        h *= 2
    return h  # pragma: no cover - p is unbounded on that side


def _newton_on_bracket(p: Callable[[float], float], dp: Callable[[float], float], lo: float,
                       hi: float, h: float) -> float:
    """The root of the increasing ``p`` in ``[lo, hi]`` (``p(lo) ≤ 0 ≤ p(hi)``) from ``h``:
    Newton steps, a bisection whenever a step would leave the bracket or does not halve the
    step before it (Press et al., *Numerical Recipes*, §9.4 ``rtsafe``)."""
    h = min(max(h, lo), hi)
    step = previous = hi - lo
    for _ in range(MAX_STEINER):
        f, d = p(h), dp(h)
        if f == 0:
            return h
        if f < 0:
            lo = h
        else:
            hi = h
        if d > 0 and lo < h - f / d < hi and abs(2 * f) <= abs(previous * d):
            previous, step = step, f / d
            new = h - step
        else:
            previous, step = step, 0.5 * (hi - lo)
            new = lo + step
        if abs(new - h) <= 2 * np.finfo(float).eps * abs(new):
            return new
        h = new
    return h


# ---- the offset mesh -----------------------------------------------------------------------


def _volume_slope(Y: np.ndarray, F: np.ndarray, n: np.ndarray) -> float:
    """``dV/dh = ⅙ Σ_f N_f · (n_a + n_b + n_c)`` of the mesh ``Y + h n`` (closed)."""
    N = face_normals(Y, F)
    return float(np.einsum("ij,ij->", N, n[F[:, 0]] + n[F[:, 1]] + n[F[:, 2]]) / 6)


def _polish(X: np.ndarray, F: np.ndarray, n: np.ndarray, h: float, target: float
            ) -> tuple[float, float, int]:
    """Newton steps on the mesh's own volume ``V(X + h n) = target`` from ``h``, until
    ``|V − target| ≤ RTOL · target``, the residual stops shrinking, or ``MAX_POLISH``
    steps: ``(h, volume, steps taken)`` of the best."""
    vol = signed_volume(X + h * n, F)
    best = (abs(vol - target), h, vol)
    steps = 0
    while best[0] > RTOL * target and steps < MAX_POLISH:
        slope = _volume_slope(X + h * n, F, n)
        if not slope > 0:
            break
        h = h - (vol - target) / slope
        steps += 1
        vol = signed_volume(X + h * n, F)
        if not abs(vol - target) < best[0]:
            break
        best = (abs(vol - target), h, vol)
    return best[1], best[2], steps


def _check_orientation(N0: np.ndarray, X: np.ndarray, F: np.ndarray, n: np.ndarray, h: float,
                       e: int, volume: float, target: float) -> None:
    """``ValueError`` naming ``target`` when the offset ``h`` turns a face over (its normal
    before and after at an angle of 90° or more; faces of zero area are left out). The mesh
    ``X`` is the input scaled by ``2**-e`` (``volume``, ``target`` and the message unscaled)."""
    N1 = face_normals(X + h * n, F)
    flipped = np.einsum("ij,ij->i", N0, N1) <= 0
    flipped &= N0.any(axis=1)
    k = int(np.count_nonzero(flipped))
    if k:
        raise _too_large(volume, target, f"the offset {_unscaled(h, e):.4g} turns {k} of "
                         f"{len(F)} faces inside out: the mesh is thinner or more curved than "
                         f"that somewhere")


# ---- the public function -------------------------------------------------------------------


def _scale_exponent(V: np.ndarray) -> int:
    """``e`` such that ``V · 2**-e`` has its largest coordinate in [1, 2) (exact scaling: the
    volumes neither overflow nor underflow, whatever the mesh's units)."""
    largest = float(np.abs(V).max(initial=0.0))
    e = int(np.frexp(largest)[1]) - 1 if largest > 0 else 0
    return max(-1000, min(1000, e))


def compensate_volume(mesh: AnyMesh, target: float) -> tuple[Mesh, CompensationReport]:
    r"""Give a closed mesh the volume ``target`` by moving every vertex the same distance
    ``h`` along its unit normal (global volume compensation, Zhuo 2014 §2.2.2 and ch. IX).

    Lengths are in the mesh's units, volumes in those units cubed.

    1. **Steiner's offset.** The parallel surface at distance ``h`` of a closed surface
       encloses ``V(h) = V + A h + M h² + (G/3) h³`` (Steiner's formula): ``A`` the area,
       ``M = ∫ H dA`` the total mean curvature, here ``½ Σ_edges |e| θ_e`` with ``θ_e`` the
       signed exterior dihedral angle (exact for convex polyhedra; Schneider, *Convex Bodies*,
       §4.2; Meyer et al. 2003), ``G = 2πχ`` (Gauss–Bonnet; the cubic term is ``(2πχ/3) h³``,
       which is ``(4π/3) h³`` on a sphere). ``h`` is the root of ``V(h) = target`` on the
       branch through 0 where ``V`` grows with ``h`` (the root nearest 0).
    2. **The mesh's volume.** Each vertex moves to ``x_i + h n_i``, ``n_i`` the area-weighted
       unit vertex normal ``Σ_{f∋i} A_f n̂_f / |…|``; that mesh's volume is a cubic in ``h``
       too, with ``dV/dh = Σ_i n_i · ∂V/∂x_i``, ``∂V/∂x_i = ⅓ Σ_{f∋i} A_f n̂_f``. Newton steps
       on it from Steiner's ``h`` (at most 8; 2–4 in practice) bring the volume to
       ``|V − target| ≤ 1e-12 · target``.

    Parameters
    ----------
    mesh : spinal.Mesh, trimesh.Trimesh or ``(vertices, faces)``
        A closed, consistently wound mesh enclosing a positive volume (outward normals);
        not modified (read-only arrays are fine). Otherwise ``ValueError`` naming ``mesh``.
    target : float
        The volume to reach, ``> 0`` and finite (``TypeError``/``ValueError`` naming
        ``target`` otherwise).

    Returns
    -------
    (Mesh, CompensationReport)
        A new :class:`spinal.Mesh` with the offset vertices and the same faces, and the
        offset, volumes, Steiner's offset and the Newton steps taken.

    Raises
    ------
    ValueError
        Naming ``target`` when the change is too large for a normal offset: Steiner's cubic
        turns back before it reaches ``target`` (a surface of genus ≥ 2 grown too far), or
        the offset turns faces inside out (shrinking past the mesh's thinnest part or its
        sharpest concave curvature, or growing past a sharp concave crease). Crossings
        between distant parts of the surface are not looked for: see
        :meth:`spinal.Mesh.self_intersections`.
    """
    V, F = mesh_arrays(mesh)
    target = as_positive(target, "target")
    _core.mesh_closed_centroid(V, F)  # ValueError "mesh: ..." unless closed and outward
    e = _scale_exponent(V)
    X = np.ldexp(V, -e)
    t = _unscaled(target, -3 * e)
    coefficients = steiner_coefficients(X, F)
    before = _unscaled(coefficients[0], 3 * e)
    if not 0 < t < np.inf:
        raise _too_large(before, target, "the ratio of the volumes is out of float64's range")
    h0 = steiner_offset(coefficients, t, e)
    N0 = face_normals(X, F)
    n = vertex_normals(X, F, N0)
    _check_orientation(N0, X, F, n, h0, e, before, target)
    h, after, steps = _polish(X, F, n, h0, t)
    _check_orientation(N0, X, F, n, h, e, before, target)
    W = _unscaled(X + h * n, e)
    if not np.isfinite(W).all():
        raise _too_large(before, target, "the offset vertices overflow float64")
    report = CompensationReport(_unscaled(h, e), before, _unscaled(after, 3 * e), target,
                                _unscaled(h0, e), steps)
    return Mesh(W, F.copy()), report
