"""Write the gallery notebooks (this file is the source of truth for their cells) and execute
them, storing their outputs, so that they show their pictures without being run (on the web
view and in the API reference). Run from the repository root:

    python tools/make_notebooks.py                  # write and execute every notebook
    python tools/make_notebooks.py 01_frames 06     # only these (by name or number)
    python tools/make_notebooks.py --no-execute     # cells only, no outputs

Execution uses nbclient (``pip install -e '.[test]'``) with pyvista off-screen. The stored
outputs are tidied: no stderr streams (progress lines, warnings), no timing metadata, and
pictures re-encoded as small palette PNGs. ``tests/api/test_notebooks.py`` checks that the
committed notebooks' cells equal the ones written here and that they hold outputs; the test
suite also executes them (nbmake). ``SPINAL_WRITE_IMAGES=1`` while executing them refreshes
the README's pictures in docs/images/.
"""

from __future__ import annotations

import argparse
import base64
import io
import os
import pathlib
import sys

import nbformat as nbf

SETUP = """import os
import numpy as np
import pyvista as pv
import spinal

pv.OFF_SCREEN = True
pv.set_jupyter_backend("static")
# set SPINAL_WRITE_IMAGES=1 to refresh the README's pictures in docs/images/
IMAGES = os.environ.get("SPINAL_WRITE_IMAGES") and os.path.join("..", "docs", "images")"""


def nb(cells):
    book = nbf.v4.new_notebook()
    book.metadata["kernelspec"] = {"display_name": "Python 3", "language": "python",
                                   "name": "python3"}
    book.cells = [nbf.v4.new_markdown_cell(c[3:]) if c.startswith("md:") else
                  nbf.v4.new_code_cell(c) for c in cells]
    return book


# Notebook 01 sets up pyvista itself (only its last cell renders), so it does not use SETUP.
frames = nb([
    """md:# Frames along a curve with spinal

`spinal.frames(points)` returns one rotation matrix per sample, columns `(r, s, t)`: `t` the unit tangent,
`r` the reference vector, `s = t × r`. This notebook compares the Frenet frame with the rotation-minimising
frame (RMF) on a curve with an inflection, and measures the convergence order of the RMF methods against the
closed-form RMF of a helix.""",
    """import numpy as np
import matplotlib.pyplot as plt
import spinal
from spinal.curves import Bezier, Helix""",
    """md:## Frenet vs RMF on a curve with an inflection

The Frenet normal points to the centre of curvature, so it flips across the inflection of this S-shaped
space curve. The RMF (double reflection, the default) turns as little as possible about the tangent.""",
    """s_curve = Bezier([[0, 0, 0], [1, 1.5, 0.3], [2, -1.5, 0.6], [3, 0, 0.9]])
u = np.linspace(0, 1, 201)
x = s_curve.point(u)
frenet = spinal.frames(s_curve, u=u, method="frenet")
rmf = spinal.frames(x)

def turning(F):  # angle between consecutive reference vectors (rad)
    return np.arccos(np.clip(np.einsum("ij,ij->i", F[1:, :, 0], F[:-1, :, 0]), -1, 1))

fig, ax = plt.subplots(figsize=(6, 3.2), layout="constrained")
ax.plot(u[1:], turning(frenet), label="Frenet")
ax.plot(u[1:], turning(rmf), label="RMF (double reflection)")
ax.set_xlabel("u"); ax.set_ylabel("turn of r per step (rad)"); ax.legend()
print("largest step: Frenet %.3f rad, RMF %.4f rad" % (turning(frenet).max(), turning(rmf).max()))
assert turning(rmf).max() < 0.1 < turning(frenet).max()""",
    """md:## Convergence against the closed-form helix RMF

The RMF of a helix is its Frenet frame turned by `−τ s`. Double reflection and RK4 are 4th order,
the rotation and projection methods 2nd order.""",
    """helix = Helix(1.0, 0.5)
c = np.hypot(1.0, 0.5)
ns = np.array([32, 64, 128, 256, 512, 1024])
errors = {m: [] for m in ["double_reflection", "rk4", "rotation", "projection"]}
for n in ns:
    u = np.linspace(0, 20 / c, n + 1)
    exact = helix.rmf(u)[:, :, 0]
    for m in errors:
        F = (spinal.frames(helix, u=u, method=m) if m == "rk4"
             else spinal.frames(helix.point(u), helix.d1(u), method=m, initial=exact[0]))
        errors[m].append(np.linalg.norm(F[:, :, 0] - exact, axis=1).max())
fig, ax = plt.subplots(figsize=(6, 4.2), layout="constrained")
for m, e in errors.items():
    order = np.log2(e[-2] / e[-1])
    ax.loglog(20 / ns, e, "o-", label=f"{m} (order {order:.2f})")
ax.xaxis.set_minor_formatter(plt.NullFormatter())   # decade labels only: no overlap
ax.set_xlabel("step h"); ax.set_ylabel("max |r - r_exact|"); ax.legend(fontsize=8)
assert abs(np.log2(errors["double_reflection"][-2] / errors["double_reflection"][-1]) - 4) < 0.05""",
    """md:## A ribbon along the RMF, rendered off-screen with PyVista""",
    """import os
import pyvista as pv
pv.OFF_SCREEN = True
pv.set_jupyter_backend("static")
knot = spinal.curves.TorusKnot()
x = knot.sample(1025)
F = spinal.frames(x, closed=True)
w = 0.04
pts = np.empty((2 * len(x), 3)); pts[0::2] = x - w * F[:, :, 0]; pts[1::2] = x + w * F[:, :, 0]
ribbon = pv.StructuredGrid(pts[:, 0].reshape(-1, 2), pts[:, 1].reshape(-1, 2), pts[:, 2].reshape(-1, 2))
pl = pv.Plotter(window_size=(500, 400))
pl.add_mesh(ribbon, scalars=np.tile(np.arange(len(x)), 2), cmap="viridis",  # grid order: edge by edge
            scalar_bar_args={"title": "sample index", "n_labels": 2, "fmt": "%.0f"})
if os.environ.get("SPINAL_WRITE_IMAGES"):  # refresh the README picture
    pl.screenshot(os.path.join("..", "docs", "images", "ribbon.png"))
pl.show()""",
])

tubes = nb([
    """md:# Tubes of a fibre bundle

Streamlines, fibre tracts and vessels are drawn as tubes. `spinal.tube` takes all curves of a
bundle in one call (flat points plus `lengths`), builds them in parallel and returns one
watertight triangle mesh with smooth-surface normals and texture coordinates. Here: 300
streamlines of a steady vortex, each tube's radius following the local flow speed.""",
    SETUP,
    """md:## Streamlines of a vortex

A Burgers-like vortex: swirl about the z axis, inflow towards it, lift along it. Streamlines
are traced with a fixed-step RK4 in NumPy (enough for a picture).""",
    """def velocity(p):
    x, y, z = p[..., 0], p[..., 1], p[..., 2]
    r2 = x**2 + y**2
    swirl = (1 - np.exp(-r2 / 0.3)) / np.maximum(r2, 1e-9)
    return np.stack([-y * swirl - 0.15 * x, x * swirl - 0.15 * y, 0.3 + 0 * z], axis=-1)

rng = np.random.default_rng(7)
a = rng.uniform(0, 2 * np.pi, 300)
rad = rng.uniform(0.4, 1.6, 300)
p = np.c_[rad * np.cos(a), rad * np.sin(a), rng.uniform(-0.5, 0.0, 300)]
steps, h = 160, 0.05
lines = np.empty((steps, 300, 3))
for k in range(steps):
    lines[k] = p
    k1 = velocity(p); k2 = velocity(p + h / 2 * k1); k3 = velocity(p + h / 2 * k2); k4 = velocity(p + h * k3)
    p = p + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
curves = lines.transpose(1, 0, 2)           # (300 curves, 160 points, 3)
points = curves.reshape(-1, 3)
speed = np.linalg.norm(velocity(points), axis=1)
lengths = np.full(300, steps)
points.shape""",
    """md:## One call for the whole bundle

`radius` may vary per point; the normals are those of the smooth tube, tilted by the
radius slope.""",
    """radius = 0.004 + 0.006 * speed / speed.max()
mesh = spinal.tube(points, radius, sides=10, lengths=lengths)
print(mesh)
print("watertight:", mesh.is_watertight, " volume:", round(mesh.volume, 6))
tm = mesh.to_trimesh()
print("trimesh agrees:", tm.is_watertight, tm.is_winding_consistent, round(tm.volume, 6))""",
    """md:Per-point values go onto the mesh with `point_data=`: every vertex of a ring (caps included)
gets its sample's value, so the flow speed colours the tubes without index arithmetic.""",
    """mesh = spinal.tube(points, radius, sides=10, lengths=lengths, point_data={"speed": speed})
poly = mesh.to_pyvista()
pl = pv.Plotter(window_size=(640, 480))
pl.add_mesh(poly, scalars="speed", cmap="magma", smooth_shading=True,
            scalar_bar_args={"title": "flow speed", "n_labels": 2, "fmt": "%.2f"})
pl.view_isometric()
pl.camera.zoom(1.2)
if IMAGES:
    pl.screenshot(os.path.join(IMAGES, "tubes.png"))
pl.show()""",
    """md:## Against the volume integral

For one tube the enclosed volume tends to `∫ A(ρ(s)) ds` (the polygon's area for the radius
at each arc length) at second order in the spacing.""",
    """c = curves[0]
r = radius[:steps]
one = spinal.tube(c, r, sides=10)
seg = np.linalg.norm(np.diff(c, axis=0), axis=1)
area = 0.5 * 10 * np.sin(2 * np.pi / 10) * r**2
integral = np.sum(0.5 * (area[1:] + area[:-1]) * seg)
print(f"tube volume {one.volume:.6e}, trapezoid integral {integral:.6e}, "
      f"relative difference {abs(one.volume / integral - 1):.1e}")""",
    """md:## A tractography bundle coloured by orientation

Tractograms come as a list of streamlines of different lengths, often float32 (nibabel's
`ArraySequence`). `spinal.tube` takes that list as it is. Here the fornix bundle shipped
with dipy (300 streamlines) when dipy is installed, otherwise a generated fornix-like arch
of the same size. Curves too short to sweep (0 or 1 point) are refused by default;
`on_short="skip"` leaves them out with a warning that names them.""",
    """try:
    import nibabel as nib
    from dipy.data import get_fnames

    streamlines = nib.streamlines.load(get_fnames(name="fornix")).streamlines
    source = "dipy's fornix"
except ImportError:  # a fornix-like arch: 300 noisy, smooth C-shaped float32 streamlines
    rng = np.random.default_rng(3)
    streamlines = []
    for _ in range(300):
        n = int(rng.integers(40, 120))
        th = np.linspace(0.2, np.pi - 0.2, n) + rng.normal(0, 0.05)
        r = 20 + rng.normal(0, 1.5)
        wobble = np.cumsum(rng.normal(0, 0.08, (n, 3)), axis=0)
        arch = np.c_[r * np.cos(th), 8 * np.sin(2 * th) + rng.normal(0, 2), 25 * np.sin(th)]
        streamlines.append((arch + wobble).astype(np.float32))
    source = "a generated fornix-like bundle"
streamlines = list(streamlines) + [np.zeros((1, 3), np.float32)]  # and one stray point
print(source, "-", len(streamlines), "streamlines,",
      sum(len(s) for s in streamlines), "points, dtype", streamlines[0].dtype)""",
    """md:The usual colouring of fibres: the absolute unit tangent as RGB (left–right red,
front–back green, up–down blue). The tangents are the frames' third column, one call for
the whole list; the per-point colours go in through `point_data` and come out on every
vertex. `mesh.sample_of` / `mesh.curve_of` give the streamline point and the streamline of
every vertex, `mesh.cell_data["curve_id"]` the streamline of every face.""",
    """import warnings

long = [s for s in streamlines if len(s) >= 2]
rgb = np.abs(spinal.frames(long)[:, :, 2])  # frames of every point of every streamline
rgb = np.vstack([rgb, [[0, 0, 0]]])          # a colour for the stray point, skipped below
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    fibres = spinal.tube(streamlines, 0.25, sides=8, on_short="skip",
                         point_data={"orientation": rgb})
print(caught[0].message)
print(fibres, "skipped:", fibres.skipped_curves)
assert np.array_equal(fibres.point_data["orientation"], rgb[fibres.sample_of])
print("watertight:", fibres.is_watertight, " volume:", round(fibres.volume, 3),
      " area:", round(fibres.area, 3))""",
    """poly = fibres.to_pyvista()
pl = pv.Plotter(window_size=(640, 480))
pl.add_mesh(poly, scalars="orientation", rgb=True, smooth_shading=True)
pl.view_isometric()
pl.camera.zoom(1.4)
if IMAGES:
    pl.screenshot(os.path.join(IMAGES, "fibres_orientation.png"))
pl.show()""",
    """md:`Mesh.save` writes the attributes too: as vertex and face properties of a PLY file, or as
point and cell data of a VTK XML PolyData file (`.vtp`, for ParaView), without VTK.""",
    """import tempfile

with tempfile.TemporaryDirectory() as tmp:
    back = pv.read(fibres.save(os.path.join(tmp, "fibres.vtp")))
print(back.array_names)
print("same colours:", np.array_equal(back.point_data["orientation"],
                                       fibres.point_data["orientation"]))""",
    """md:## Rough curves: sharp corners as joins

Real polylines are rarely smooth: coarse streamlines, GPS tracks and polymer chains turn by
tens of degrees between samples. At such a corner one ring per sample would cross its
neighbours on the inner side. `spinal.tube` builds the corner as a join instead, like a 2D
stroker: the inner side is cut where the two straight tubes meet (in the corner's bisector
plane), the outer side is a round join (`join="round"`, the default; or `"bevel"`,
`"miter"`). Below, 40 Gaussian random walks through spinal and through VTK's tube filter
(PyVista), and the pairs of crossing triangles that libigl's exact predicates find in each.""",
    """rng = np.random.default_rng(2)
walks = [np.cumsum(rng.normal(size=(int(rng.integers(5, 25)), 3)), axis=0) for _ in range(40)]
with warnings.catch_warnings():
    warnings.simplefilter("ignore", spinal.FoldOverWarning)
    joined = spinal.tube(walks, 0.08, sides=16)
print(joined, "watertight:", joined.is_watertight)

try:
    import igl
    import igl.predicates

    def crossing_pairs(v, f):
        v = np.ascontiguousarray(v, dtype=np.float64)
        f = np.ascontiguousarray(f, dtype=np.int64)
        return len(igl.predicates.find_self_intersections(v, f)[1])

    # each walk's tube against itself (the walks of a bundle cross each other in space)
    ours, theirs = [], []
    for c, w in enumerate(walks):
        f = joined.faces[joined.cell_data["curve_id"] == c]
        ours.append(crossing_pairs(joined.vertices, f))
        vtk = pv.lines_from_points(w).tube(radius=0.08, n_sides=16, capping=True)
        vtk = vtk.triangulate().clean()
        theirs.append(crossing_pairs(vtk.points, vtk.faces.reshape(-1, 4)[:, 1:]))
    ours, theirs = np.array(ours), np.array(theirs)
    print(f"walks whose tube crosses itself: spinal {np.sum(ours > 0)}, VTK {np.sum(theirs > 0)}")
    print(f"crossing triangle pairs: spinal {ours.sum()}, VTK {theirs.sum()}")
except ImportError:
    print("libigl is not installed: no crossing count")""",
    """md:The pairs spinal still has are where a walk's tube really meets itself (two segments
closer than the diameter) or a hairpin tighter than the radius, which a `FoldOverWarning`
names. One corner of 137° up close, sampled every 0.05: spinal's round join on the left; on
the right VTK's rings, one per sample: the corner pinches, and the rings next to it fold
through each other on the inner side.""",
    """corner = np.r_[np.c_[np.linspace(-1, 0, 21), np.zeros(21), np.zeros(21)],
               np.linspace(0, 1, 21)[1:, None] * [np.cos(2.4), np.sin(2.4), 0]]
ours = spinal.tube(corner, 0.1, sides=24).to_pyvista()
theirs = pv.lines_from_points(corner).tube(radius=0.1, n_sides=24, capping=True)
pl = pv.Plotter(shape=(1, 2), window_size=(900, 420))
for i, (m, name) in enumerate([(ours, "spinal, round join"), (theirs, "VTK tube filter")]):
    pl.subplot(0, i)
    pl.add_mesh(m, color="lightsteelblue", show_edges=True, edge_color="gray", line_width=0.5)
    pl.add_text(name, font_size=10)
    pl.camera_position = [(0.1, -0.5, 1.3), (-0.15, 0.1, 0), (0, 1, 0)]
pl.show()""",
])

knot = nb([
    """md:# A closed knot tube without a seam

On a closed curve the rotation-minimising frame does not close: after one circuit it has
turned by the closing angle. `spinal.frames(..., closed=True)` spreads that angle linearly in
arc length, so a closed tube meets itself without a twist at the seam; `split_seams=True`
duplicates the seam vertices so a texture wraps without a jump.""",
    SETUP,
    """knot = spinal.curves.TorusKnot()
x = knot.sample(801)                                   # first point repeated at the end
print("closing angle of the RMF:", round(spinal.closing_angle(x), 6), "rad")
tube = spinal.tube(x, 0.12, sides=24, closed=True)
print(tube, "watertight:", tube.is_watertight)""",
    """md:## The seam: the last ring joins the first rail for rail

The closing quads (from the last ring back to the first) are shaped like their neighbours:
the rails run straight through the seam, with no twist.""",
    """V = tube.vertices.reshape(800, 24, 3)
rail = np.linalg.norm(np.diff(np.concatenate([V, V[:1]]), axis=0), axis=2)
for k in (797, 798, 799, 0, 1):
    print(f"rail edges from ring {k:3d}:", rail[k].round(5)[:6])""",
    """md:## A checkerboard wraps without a jump

With `split_seams=True` the texture coordinates run from u = 0 to the loop's length and from
v = 0 to 1 around, and no face spans the seam.""",
    """tex = spinal.tube(x, 0.12, sides=24, closed=True, split_seams=True)
poly = tex.to_pyvista()
uv = tex.uv / [tex.uv[:, 0].max() / 40, 1 / 4]
checker = ((np.floor(uv[:, 0]) + np.floor(uv[:, 1])) % 2).astype(float)
poly["checker"] = checker
pl = pv.Plotter(window_size=(640, 480))
pl.add_mesh(poly, scalars="checker", cmap=["#20304a", "#e9c46a"], show_scalar_bar=False,
            smooth_shading=True)
pl.view_isometric()
if IMAGES:
    pl.screenshot(os.path.join(IMAGES, "knot.png"))
pl.show()""",
])

quat = nb([
    """md:# Quaternion frames, cameras and a walk on a mesh

`spinal.quaternions` writes frames as unit quaternions (scipy's component order by default),
keeps their signs continuous along a curve, interpolates them by slerp, transports them with
a quaternion recurrence, measures their total turning as a length on S³, flies a camera along
a path and walks on a triangle mesh.""",
    SETUP + "\nfrom spinal import quaternions as Q\nimport matplotlib.pyplot as plt",
    """md:## Frenet and parallel transport as curves on S³

On a helix the Frenet quaternion curve has length π per turn for any pitch; parallel
transport turns less, `½∫κ ds = πa/c`.""",
    """helix = spinal.curves.Helix(1.0, 0.5, turns=2)
x = helix.sample(400)
q_pt = Q.quaternion_frames(x)
q_fr = Q.quaternion_frames(x, method="frenet")
print("path length per turn: Frenet %.4f (π = %.4f), transport %.4f (πa/c = %.4f)" % (  # estimated tangents
    Q.quaternion_length(q_fr) / 2, np.pi, Q.quaternion_length(q_pt) / 2, np.pi / np.hypot(1, 0.5)))
fig, ax = plt.subplots(1, 2, figsize=(9, 3), sharey=True)
for a, q, title in zip(ax, (q_fr, q_pt), ("Frenet", "parallel transport")):
    a.plot(q); a.set_title(title); a.set_xlabel("sample")
ax[0].legend(["x", "y", "z", "w"]); plt.tight_layout()""",
    """md:## A camera flying through a knot

`camera_frames` returns camera-to-world rotations (columns right, up, −gaze); the transport
mode is the frame a viewer flies with, closed up over the loop.""",
    """knot = spinal.curves.TorusKnot().sample(600)
cam = Q.camera_frames(knot, closed=True)
tube = spinal.tube(knot, 0.15, 24, closed=True).to_pyvista()
pl = pv.Plotter(window_size=(480, 360))
pl.add_mesh(tube, color="#7aa6c2", smooth_shading=True)
i = 120                                  # the camera's pose at sample i: behind it and above
right, up, back = cam[i].T
pl.add_mesh(pv.Sphere(radius=0.2, center=knot[i]), color="crimson")  # where the viewer is
pl.add_arrows(knot[i][None], -back[None], mag=0.8, color="crimson")   # and where it looks
pl.camera.position = knot[i] + 4.0 * back + 2.5 * up
pl.camera.focal_point = knot[i] - 1.0 * back
pl.camera.up = up
pl.reset_camera()                # the same direction, moved back until the whole knot fits
pl.show()""",
    """md:## Pythagorean-hodograph cubics: rational frames

`spinal.ph.fit` turns a curve into a G¹ spline of PH cubics within a tolerance; on PH cubics
the rotation-minimising frame has a closed-form angle and a rational approximation, so the
swept surface has an exact rational Bézier form. The spline's RMF is compared here with the
true RMF of the helix (RK4 on the exact curve) at the joints, over three turns.""",
    """helix = spinal.curves.Helix(1.0, 0.5, turns=3)
spline = spinal.ph.fit(helix, tol=1e-5)
print(spline, " largest deviation from the helix: %.2e" % spline.deviation.max())
joints = np.arange(spline.segments + 1.0)               # s at the joints, u = spline.knots
F_ph = spline.rmf(joints)                                # rational RMF
F_true = spinal.frames(helix, u=spline.knots, method="rk4", initial=F_ph[0][:, 0])
print("angle between the PH spline's RMF and the helix's RMF at the joints: max %.2e rad" %
      np.abs(Q.spin(F_true, F_ph)).max())
mesh = spline.sweep(0.15 * np.array([[1, 0], [0, 1], [-1, 0], [0, -1.0]]))
print(mesh, "watertight:", mesh.is_watertight)
from PIL import Image                   # off-screen, Mesh.plot returns the picture as an array
Image.fromarray(mesh.plot(screenshot=os.path.join(IMAGES, "ph_sweep.png") if IMAGES else None,
                          window_size=(480, 360)))""",
    """md:## Walking on a torus

The walker's frame is rotated across every edge by the dihedral angle, so its path is straight
in the unfolded faces and its frame turns without twist.""",
    """import trimesh
torus = trimesh.creation.torus(major_radius=2, minor_radius=0.7, major_sections=64, minor_sections=32)
start = 10
p0 = torus.vertices[torus.faces[start]].mean(axis=0)
walk = Q.walk_mesh(torus.vertices, torus.faces, start, p0, [[0.05, 0.02]] * 400)
print("stopped at a boundary:", walk.stopped.any(), " edge crossings:", len(walk.path) - 401)
pl = pv.Plotter(window_size=(640, 400))
pl.add_mesh(pv.wrap(torus), color="white", opacity=0.6)
pl.add_mesh(pv.lines_from_points(walk.path), color="crimson", line_width=3)
pl.view_isometric()
if IMAGES:
    pl.screenshot(os.path.join(IMAGES, "walk.png"))
pl.show()""",
])


deform = nb([
    """md:# Volume-preserving deformation with divergence-free fields

`spinal.fields` builds closed-form velocity fields with zero divergence; `spinal.advect` moves
points along them (RK4 in Rust, in parallel). The continuous flow preserves every volume, so a
mesh deformed this way keeps its volume up to the integration error (RK4, O(h⁴)) and the
mesh error (the triangles follow the flow only at their vertices). Here a spherical tool
starts just outside a unit sphere and pushes a dent into it: points near the tool move with
its surface, so the surface never crosses the tool.""",
    SETUP + "\nimport trimesh, igl\nimport matplotlib.pyplot as plt",
    """sphere = trimesh.creation.icosphere(subdivisions=5)      # 10,242 vertices
V0, F = sphere.vertices, sphere.faces
vol0 = sphere.volume
tool = spinal.fields.translation(center=[1.75, 0, 0], radius=0.6, velocity=[-0.5, 0, 0])
V, t, rows = V0.copy(), 0.0, []
for k in range(12):                  # twelve frames of an animation, 0.1 time units each
    V = spinal.advect(V, tool, 0.1, t0=t)
    t += 0.1
    tv = trimesh.Trimesh(V, F, process=False).volume
    _, iv = igl.centroid(V, F)
    rows.append((t, tv / vol0 - 1, float(iv) / vol0 - 1))
rows = np.array(rows)
print("relative volume change after t = %.1f: trimesh %.2e, libigl %.2e" % tuple(rows[-1]))""",
    """md:## Volume over time

The change stays at the level of the mesh error of a 10k-vertex sphere; the tool's fields
are exactly divergence-free.""",
    """fig, ax = plt.subplots(figsize=(6, 3))
ax.plot(rows[:, 0], rows[:, 1], "o-", label="trimesh")
ax.plot(rows[:, 0], rows[:, 2], "x--", label="libigl")
ax.set_xlabel("time"); ax.set_ylabel("relative volume change"); ax.legend(); plt.tight_layout()""",
    """md:## Integration error vs mesh error

Against a run with 400 steps, the vertex error falls with the step while the volume change
stays put: what remains is the mesh's error. With the thesis' falloff `(R − |d|)²` the field
is only C⁰ at the edge of its reach, and RK4 drops to 2nd order for the points that cross it
(≈4× per halving); `falloff_power=4` makes the field C² and RK4 4th order (≈16×).""",
    """for power in (2, 4):
    f = spinal.fields.translation(center=[1.75, 0, 0], radius=0.6, velocity=[-0.5, 0, 0],
                                  falloff_power=power)
    ref = spinal.advect(V0, f, 1.2, steps=400)
    for steps in (6, 12, 24, 48):
        W = spinal.advect(V0, f, 1.2, steps=steps)
        print(f"falloff power {power}, {steps:3d} steps: max vertex error "
              f"{np.abs(W - ref).max():.2e}, volume change "
              f"{trimesh.Trimesh(W, F, process=False).volume / vol0 - 1:+.2e}")""",
    """pl = pv.Plotter(window_size=(560, 420))
pl.add_mesh(pv.wrap(trimesh.Trimesh(V, F, process=False)), color="#d9a066", smooth_shading=True)
pl.camera_position = [(3.2, -2.2, 1.6), (0, 0, 0), (0, 0, 1)]
pl.camera.zoom(0.8)
if IMAGES:
    pl.screenshot(os.path.join(IMAGES, "deform.png"))
pl.show()""",
    """md:## Progress of long runs

`progress=True` shows a tqdm bar (notebook-aware) when tqdm is installed and a text line
`advect: done/total steps` on stderr otherwise; a callable is called as
`progress(done_steps, total_steps)` about a hundred times per run, for a progress display of
one's own.""",
    """W = spinal.advect(V0, tool, 1.2, steps=400, progress=True)
updates = []
W2 = spinal.advect(V0, tool, 1.2, steps=400, progress=lambda done, total: updates.append(done))
print(f"{len(updates)} updates of the callable, the last at {updates[-1]} of 400 steps")
# the run is done in blocks between updates: only the step times' rounding differs
print("largest difference from a run without progress: %.1e" %
      np.abs(W2 - spinal.advect(V0, tool, 1.2, steps=400)).max())""",
    """md:## Refinement: `spinal.deform`

Where the flow stretches the mesh its triangles no longer follow the surface, and that is
the remaining volume error. `spinal.deform` advects the mesh and, after every RK4 step,
splits each edge longer than `refine × max(its rest length, the mean rest edge)` (longest
edge first, both triangles bisected): the new vertex is the edge's *rest* midpoint carried by
the steps so far, then carried on with the mesh. `estimate=True` splits the volume change
into integration error (Richardson, from a run with twice the steps) and mesh error.""",
    """change = {}
for refine in (None, 1.5, 1.0):
    dented, report = spinal.deform(sphere, tool, 1.2, refine=refine, estimate=True)
    change[refine] = report.relative_change
    print(f"refine={refine}:", report)
assert abs(change[1.0]) < abs(change[1.5]) < abs(change[None]) / 3""",
    """md:## A large drag stays resolved

A tool of radius 0.9 centred on the sphere's surface is dragged half a radius sideways. The
material inside the tool moves with it and the material outside slips past its surface, so
the flow tears the surface along the tool: no rest point lands in the opened strip, whose
boundary runs along the tool's surface. The refinement fills it with new vertices placed on
that surface (`slip_vertices`), which move along it with a blend of the two sides'
velocities; a torn edge is split halfway along its path over the two sides and the surface,
so bisection shortens it and the refinement converges. The work is bounded by
`max_vertices` (default 8× the input) and `max_passes`: when a bound leaves edges over the
threshold the report says `converged=False` with their number, and a
`spinal.RefinementWarning` is emitted. The volume stays within 5e-4; the opened strip is the
band along the tool's surface in the picture.""",
    """import time, warnings
drag = spinal.fields.translation(center=[0, 0, 0.9], radius=0.9, velocity=[0.5, 0, 0])
_, plain = spinal.deform(sphere, drag, 1.0, refine=None)
clock = time.perf_counter()
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    dragged, report = spinal.deform(sphere, drag, 1.0)
seconds = time.perf_counter() - clock
area = trimesh.Trimesh(dragged.vertices, dragged.faces, process=False).area / sphere.area
n0, n1 = len(sphere.vertices), len(dragged.vertices)
print(report)
print(f"relative volume change {report.relative_change:+.2e} (unrefined {plain.relative_change:+.2e})")
print(f"vertices {n0:,} -> {n1:,} ({n1 / n0:.1f}x) for a surface-area growth of {area:.2f}x; "
      f"{report.torn_vertices:,} placed at torn edges")
print(f"converged: {report.converged} ({report.edges_over_threshold:,} edges over the threshold); "
      f"warnings: {[w.category.__name__ for w in caught]}")
print(f"{seconds:.2f} s: " + ", ".join(f"{k} {v:.3f} s" for k, v in report.timings.items()))
assert abs(report.relative_change) < 5e-4 and n1 <= 10 * n0 and report.converged""",
    """pl = pv.Plotter(window_size=(560, 420))
pl.add_mesh(pv.wrap(trimesh.Trimesh(dragged.vertices, dragged.faces, process=False)),
            color="#d9a066", smooth_shading=True)
pl.add_mesh(pv.Sphere(radius=0.9, center=(0.5, 0, 0.9)), color="#4060a0", opacity=0.15)
pl.camera_position = [(3.4, -4.2, 2.6), (0.25, 0, 0.4), (0, 0, 1)]
pl.camera.zoom(0.9)
pl.show()""",
])

flesh = nb([
    """md:# Fleshing: bending a shape along its spine, keeping every piece's volume

`spinal.flesh(vertices, rest_spine, posed_spine)` moves a shape bound to a spine with the
spine's new pose. Curve deformers in animation packages map each point rigidly with the
local frame (`solution="none"` here) and lose or gain volume wherever the shape sits off the
spine's centre line; Zhuo's correction moves the offset so that every small piece keeps its
volume (`"radial"`, `"normal"`, `"binormal"`). Volumes are measured twice, by trimesh and by
libigl (`igl.centroid` returns the centroid and the enclosed volume), after checking that the
mesh is closed and consistently wound: only then is its enclosed volume defined.""",
    SETUP + "\nfrom pathlib import Path\nimport matplotlib.pyplot as plt\nimport trimesh, igl",
    """def arc(n, length, radius):
    \"\"\"A straight spine along x and the same spine bent into a circular arc (same edge lengths,
    bending towards +y).\"\"\"
    s = np.linspace(-length / 2, length / 2, n)
    th = s / radius
    return np.c_[s, 0 * s, 0 * s], np.c_[radius * np.sin(th), radius * (1 - np.cos(th)), 0 * s]

def volumes(V, F):
    \"\"\"Enclosed volume by trimesh and by libigl, refusing meshes that do not enclose one.\"\"\"
    tm = trimesh.Trimesh(V, F, process=False)
    if not (tm.is_watertight and tm.is_winding_consistent):
        raise ValueError("the mesh is not closed and consistently wound: no enclosed volume")
    _, iv = igl.centroid(np.asarray(V, dtype=np.float64), np.asarray(F, dtype=np.int64))
    return tm.volume, float(iv)

def side_by_side(shapes, F, spine, ghost=None, image=None, camera="xy"):
    \"\"\"Render {label: vertices} next to each other with the posed spine (and the rest shape as
    a translucent ghost); write docs/images/<image> when SPINAL_WRITE_IMAGES is set.\"\"\"
    pl = pv.Plotter(shape=(1, len(shapes)), window_size=(900, 380))
    for k, (label, V) in enumerate(shapes.items()):
        pl.subplot(0, k)
        pl.add_text(label, font_size=10)
        if ghost is not None:
            pl.add_mesh(pv.wrap(trimesh.Trimesh(ghost, F, process=False)), color="grey",
                        opacity=0.25)
        pl.add_mesh(pv.wrap(trimesh.Trimesh(V, F, process=False)), color="#c8a27a",
                    smooth_shading=True)
        pl.add_mesh(pv.lines_from_points(spine), color="#3060a0", line_width=3)
        pl.camera_position = camera
    pl.link_views()
    if IMAGES and image:
        pl.screenshot(os.path.join(IMAGES, image))
    pl.show()""",
    """md:## An off-centre bar

A box centred 0.3 off the spine towards the centre of curvature (and 0.2 along it), bent
into an arc of radius 1. The uncorrected map squeezes it by the factor `1 − y/R` of the
frame's rotation about the bent spine: about −30 %. The corrections keep the volume up to
the mesh error (the box's faces are flat, the map bends them).""",
    """rest, posed = arc(301, 3.0, 1.0)
box = trimesh.creation.box(extents=[0.3, 0.3, 0.3]).subdivide().subdivide().subdivide()
box.apply_translation([0.2, 0.3, 0.0])
v0, iv0 = volumes(box.vertices, box.faces)
bent = {}
for solution in ("none", "radial", "normal", "binormal"):
    V = spinal.flesh(box.vertices, rest, posed, solution=solution)
    tv, iv = volumes(V, box.faces)
    bent[solution] = (V, tv / v0 - 1)
    print(f"{solution:9s} volume change: trimesh {tv / v0 - 1:+.4%}, libigl {iv / iv0 - 1:+.4%}")
    assert abs(tv / iv - 1) < 1e-12                    # the two volume integrals agree
assert abs(bent["radial"][1]) < 1e-3 < 0.2 < abs(bent["none"][1])
near = np.abs(rest[:, 0] - 0.2) < 0.45                 # the part of the spine beside the box
side_by_side({f"solution='{s}': {bent[s][1]:+.2%}": bent[s][0] for s in ("none", "radial")},
             box.faces, posed[near], ghost=box.vertices, image="flesh_bar.png")""",
    """md:## A second mesh: the cow, or a bunny-like stand-in

The real test mesh `cow.obj` comes from the project's shared data folder (`shared/` beside
the repository; it is not shipped with spinal). Without it the notebook builds a bunny-like
closed mesh instead: a sphere displaced along its normals by smooth lobes (head, ears, tail,
feet), an embedded surface whatever the lobes, since every direction meets it once.""",
    """def find_shared(name):
    \"\"\"shared/data/meshes/<name> beside the repository (found from spinal's source folder or
    from the working directory upwards), or None.\"\"\"
    for start in (Path(spinal.__file__).resolve().parent, Path.cwd().resolve()):
        for folder in (start, *start.parents):
            path = folder / "shared" / "data" / "meshes" / name
            if path.is_file():
                return path
    return None

def bunny_like(subdivisions=5):
    \"\"\"A closed, watertight bunny-like mesh: a unit icosphere with r(d) = 1 + Σ h exp(−(1 − d·c)/w)
    (lobes of height h about directions c, angular width ~ √w), stretched to a body along x.\"\"\"
    sphere = trimesh.creation.icosphere(subdivisions=subdivisions)
    d = sphere.vertices
    r = np.ones(len(d))
    for c, h, w in [([1.0, 0.45, 0.0], 0.3, 0.05),                                  # head
                    ([0.5, 0.8, 0.38], 0.8, 0.012), ([0.5, 0.8, -0.38], 0.8, 0.012),  # ears
                    ([-1.0, 0.25, 0.0], 0.25, 0.015),                               # tail
                    ([0.6, -0.75, 0.3], 0.15, 0.03), ([0.6, -0.75, -0.3], 0.15, 0.03),
                    ([-0.6, -0.7, 0.35], 0.2, 0.04), ([-0.6, -0.7, -0.35], 0.2, 0.04)]:
        c = np.asarray(c) / np.linalg.norm(c)
        r += h * np.exp(-(1 - d @ c) / w)
    return trimesh.Trimesh(d * r[:, None] * [1.4, 0.9, 0.8], sphere.faces, process=False)

path = find_shared("cow.obj")
if path is not None:
    name, mesh = "cow", trimesh.load(path, process=False)
    # the spine runs through the body from tail to head (the cow's up is +y), the legs hang
    # 3–4 units below it; bent into an arc of radius 8 with the legs on the outside
    rest, posed = arc(201, 11.0, 8.0)
    rest += [0.75, 0.8, 0]
    posed += [0.75, 0.8, 0]
    print("cow.obj from", Path(*path.parts[-4:]))   # shared/data/meshes/cow.obj
else:
    name, mesh = "bunny-like", bunny_like()
    # the spine runs along the back, the body below it: bent with the belly outside
    rest, posed = arc(201, 4.4, 3.0)
    rest += [0, 0.5, 0]
    posed += [0, 0.5, 0]
    print("cow.obj not found: using a generated bunny-like mesh")
print(f"{name}: {len(mesh.vertices)} vertices, watertight {mesh.is_watertight}, "
      f"consistently wound {mesh.is_winding_consistent}")
assert mesh.is_watertight and mesh.is_winding_consistent""",
    """md:## Bent along its spine

The uncorrected map stretches everything on the outside of the bend and squeezes the inside;
with the body mostly on one side of the spine the volume changes by several per cent. The
radial correction keeps it.""",
    """v0, iv0 = volumes(mesh.vertices, mesh.faces)
print(f"{name} rest volume: trimesh {v0:.6f}, libigl {iv0:.6f}")
shapes = {}
for solution in ("none", "radial"):
    V = spinal.flesh(mesh.vertices, rest, posed, solution=solution)
    tv, iv = volumes(V, mesh.faces)
    shapes[f"solution='{solution}': {tv / v0 - 1:+.3%}"] = V
    print(f"{name}, {solution:6s}: volume change trimesh {tv / v0 - 1:+.3%}, "
          f"libigl {iv / iv0 - 1:+.3%}")
    assert abs(tv / iv - 1) < 1e-12
    assert (abs(tv / v0 - 1) < 1e-4) if solution == "radial" else (abs(tv / v0 - 1) > 0.05)
side_by_side(shapes, mesh.faces, posed, image="flesh.png" if name == "cow" else None,
             camera="xy" if name == "cow" else [(1.5, 2.0, 9.0), (0.0, 0.3, 0.0), (0, 1, 0)])""",
    """md:## A snake crawling along a control-point path

The path is a Catmull–Rom spline through eight control points (`spinal.curves.Spline`),
sampled evenly in arc length. The snake — a tapered tube bound once to a straight rest
spine (`SpineBinding`) — crawls 60 steps along it: `animate` slides it by a growing arc
length per pose (`slide=`) and carries the frames from pose to pose, so the body does not
roll. Every pose keeps its volume locally (radial solution); what the flat faces between
bent vertices still lose is given back by one normal offset per pose
(`spinal.compensate_volume`, Steiner's polynomial then Newton on the mesh volume). The
uncorrected map (`solution="none"`, the rigid map of the curve deformers in animation
packages) gains or loses about κd of volume wherever the body bends, with `d` the body's
offset from the spine.""",
    """ctrl = np.array([[0, 0, 0], [2, 1.2, 0], [4, -1.0, 0.3], [6, 1.0, 0.0], [8, -0.8, -0.3],
                 [10, 0.9, 0], [12, -0.5, 0.2], [14, 0, 0]], dtype=float)
path = spinal.curves.Spline(ctrl, kind="catmull_rom")
along = path.sample_arc_length(1200)
length = 3.0
x = np.linspace(0, length, 150)
# the spine runs half a radius to one side of the body's centre line, in the plane of the bends
body = spinal.tube(np.c_[x, 0 * x + 0.06, 0 * x], 0.12 * np.sqrt(1 - (x / length) ** 2 * 0.9), 32)
V0, F = body.vertices, body.faces
rest = np.c_[np.linspace(0, length, 61), np.zeros(61), np.zeros(61)]
snake = spinal.SpineBinding(V0, rest)
steps = np.linspace(0.0, path.length - length - 0.5, 60)
poses = np.repeat(along[None], len(steps), axis=0)
crawl = {s: snake.animate(poses, slide=steps, solution=s) for s in ("radial", "none")}
v0 = spinal.Mesh(V0, F).volume
change = {s: np.array([spinal.Mesh(V, F).volume / v0 - 1 for V in crawl[s]]) for s in crawl}
compensated = [spinal.compensate_volume((V, F), v0) for V in crawl["radial"]]
change["radial + compensation"] = np.array([r.volume_after / v0 - 1 for _, r in compensated])
for s, c in change.items():
    print(f"{s:22s} volume change over the 60 poses: {c.min():+.2e} … {c.max():+.2e}")
assert np.abs(change["radial + compensation"]).max() < 1e-9
assert np.abs(change["radial"]).max() < 0.01 * np.abs(change["none"]).max()""",
    """fig, ax = plt.subplots(figsize=(7, 3))
for s, c in change.items():
    ax.plot(np.abs(c) + 1e-17, label=s)
ax.set_yscale("log")
ax.set_xlabel("pose")
ax.set_ylabel("|volume change|")
ax.legend(fontsize=8)
plt.show()
pl = pv.Plotter(window_size=(720, 320))
pl.add_mesh(pv.lines_from_points(along), color="#3060a0", line_width=2)
for k in (0, 29, 59):
    pl.add_mesh(spinal.Mesh(compensated[k][0].vertices, F).to_pyvista(), color="#6a8f3a",
                smooth_shading=True)
pl.camera_position = [(7, -9, 9), (7, 0, 0), (0, 0, 1)]
pl.show()""",
])


def curl_tools_section():
    """Notebook 04's section on the curl tools of any shape and keyframed tools."""
    return [
        """md:## Free-form curl tools and keyframed tools

The curl fields work with the signed distance `d` of any shape (and its exact gradient):
`fields.rod` (a tube about a spline axis), `fields.sdf_curl` (a sampled distance) and
`fields.mesh_curl` (a closed mesh) push the material like the sphere above, exactly
divergence-free. `fields.keyframed` moves a tool's shape rigidly through keys `(t, c, Q)`
(Hermite positions, slerped orientations). Left: a bent rod pressed into the sphere;
middle: a box given as a triangle mesh (`mesh_curl`, its distance sampled on a 64³ grid)
pressed in; right: a capsule following a curved key path across the surface while turning.""",
        """from scipy.spatial.transform import Rotation
th = np.linspace(-0.5, 0.5, 7)
axis = np.c_[np.sin(th), 0.2 * np.sin(2 * th), np.cos(th)] * 1.3
rod = spinal.fields.rod(axis, 0.15, velocity=[0, 0, -1], reach=0.3)
pressed = spinal.advect(V0, rod, 0.25)
rod_now = axis + [0, 0, -0.25]
times = np.linspace(0, 1.0, 6)
path = np.c_[np.sin(2.4 * times - 1.2), 0.4 * np.sin(3 * times), 1.15 - 0.2 * np.sin(np.pi * times)]
turns = Rotation.from_rotvec(np.outer(times, [0, 0, 2.0])).as_matrix()
cap = spinal.fields.rod([[-0.2, 0, 0], [0.2, 0, 0]], 0.12, velocity=[1, 0, 0], reach=0.25)
keyed = spinal.fields.keyframed(cap, times, path, turns)
swept = spinal.advect(V0, keyed, 1.0)
box = trimesh.creation.box([0.6, 0.6, 0.3])
box.apply_translation([0, 0, 1.2])
boxed = spinal.fields.mesh_curl((box.vertices, box.faces), velocity=[0, 0, -1])
stamped = spinal.advect(V0, boxed, 0.25)
box.apply_translation([0, 0, -0.25])   # the box at t = 0.25
for name, W in (("rod", pressed), ("mesh_curl box", stamped), ("keyframed capsule", swept)):
    tv = trimesh.Trimesh(W, F, process=False).volume
    print(f"{name}: max displacement {np.linalg.norm(W - V0, axis=1).max():.3f}, "
          f"relative volume change {tv / vol0 - 1:+.2e}")
    assert abs(tv / vol0 - 1) < 1e-3
pl = pv.Plotter(shape=(1, 3), window_size=(1300, 420))
pl.subplot(0, 0)
pl.add_mesh(pv.wrap(trimesh.Trimesh(pressed, F, process=False)), color="#c8a27a",
            smooth_shading=True)
pl.add_mesh(pv.Spline(rod_now, 100).tube(radius=0.15), color="#3060a0", opacity=0.6)
pl.subplot(0, 1)
pl.add_mesh(pv.wrap(trimesh.Trimesh(stamped, F, process=False)), color="#c8a27a",
            smooth_shading=True)
pl.add_mesh(pv.wrap(box), color="#3060a0", opacity=0.6)
pl.subplot(0, 2)
pl.add_mesh(pv.wrap(trimesh.Trimesh(swept, F, process=False)), color="#c8a27a",
            smooth_shading=True)
pl.add_mesh(pv.Spline(path, 100), color="#a03030", line_width=3)
end = path[-1] + np.array([[-0.2, 0, 0], [0.2, 0, 0]]) @ turns[-1].T   # the capsule at t = 1
pl.add_mesh(pv.Line(end[0], end[1]).tube(radius=0.12), color="#3060a0", opacity=0.6)
pl.link_views()
pl.camera_position = [(2.5, -3.0, 3.5), (0, 0, 0.3), (0, 0, 1)]
if IMAGES:
    pl.screenshot(os.path.join(IMAGES, "curl_tools.png"))
pl.show()""",
        """md:Every field can be keyframed. A shape tool (sphere, capsule, strip, torus, rod, sampled or
mesh distance) moves its shape: left, a torus slid and tilted across the top, deformed with
refinement by `spinal.deform`. A field without a shape (twist, bend, a path tool, a sum) is
carried whole, `v = Q v₀(C + Qᵀ(x − c), t)`, a rigid change of coordinates that keeps it
divergence-free: right, a twist about the vertical whose axis is turned down to the
horizontal while it acts (the sphere coloured by its starting longitude).""",
        """kt = np.linspace(0.0, 1.0, 5)
ring = spinal.fields.torus([0, 0, 1.08], [0, 0, 1], 0.45, 0.1, 1.0, reach=0.2)
kpos = np.c_[0.4 * np.sin(np.pi * (kt - 0.5)), 0 * kt, 1.08 - 0.06 * np.sin(np.pi * kt)]
kturn = Rotation.from_rotvec(np.outer(kt - 0.5, [0, 0.8, 0])).as_matrix()
slid, slid_report = spinal.deform(sphere, spinal.fields.keyframed(ring, kt, kpos, kturn), 1.0)
print("keyframed torus:", slid_report)
assert abs(slid_report.relative_change) < 5e-4
swirl = spinal.fields.twist([0, 0, 0], [0, 0, 1], 8.0, 1.6)
tilt = Rotation.from_rotvec(np.outer(kt, [0, 0.5 * np.pi, 0])).as_matrix()
carried = spinal.advect(V0, spinal.fields.keyframed(swirl, kt, np.zeros((5, 3)), tilt), 1.0)
tv = trimesh.Trimesh(carried, F, process=False).volume
print(f"carried twist: max displacement {np.linalg.norm(carried - V0, axis=1).max():.3f}, "
      f"relative volume change {tv / vol0 - 1:+.2e}")
assert abs(tv / vol0 - 1) < 1e-3
pl = pv.Plotter(shape=(1, 2), window_size=(900, 420))
pl.subplot(0, 0)
pl.add_mesh(slid.to_pyvista(), color="#c8a27a", smooth_shading=True)
ring_now = pv.ParametricTorus(0.45, 0.1).rotate_y(np.degrees(0.4)).translate(kpos[-1])
pl.add_mesh(ring_now, color="#3060a0", opacity=0.4)
pl.add_mesh(pv.Spline(kpos, 50), color="#a03030", line_width=3)
pl.camera_position = [(1.0, -3.2, 3.2), (0, 0, 0.4), (0, 0, 1)]
pl.subplot(0, 1)
longitude = np.sin(5 * np.arctan2(V0[:, 1], V0[:, 0]))
pl.add_mesh(pv.wrap(trimesh.Trimesh(carried, F, process=False)), scalars=longitude,
            cmap="copper", smooth_shading=True,
            scalar_bar_args={"title": "sin(5 x start longitude)", "n_labels": 2, "fmt": "%.1f"})
pl.camera_position = [(2.5, -3.0, 3.5), (0, 0, 0.0), (0, 0, 1)]
pl.show()""",
    ]


deform.cells += nb(curl_tools_section()).cells

scale = nb([
    """md:# Scale-out: many chunks on many processes with Dask

spinal's calls use all cores of one machine. Beyond that, a large job splits into
independent chunks that [Dask](https://docs.dask.org/) maps over worker processes, here a
`distributed.LocalCluster` on this machine, on a cluster the same code with another cluster
object (see `docs/scale-out.md`). Each task runs inside `spinal.threads(1)`, so a worker
process uses one core and the workers do not oversubscribe the machine.

Two jobs: a bundle of streamline tubes (100,000 in the full run; 8,000 here) and a
deformation animation (1,000 frames in the full run; 60 here). Each chunk is computed from
a few numbers (a seed, a slice), so only small messages travel, and each result is shown to
equal the single call bit for bit. Install with `pip install 'spinal[dask]'`.""",
    """import hashlib, time
import numpy as np
import dask, dask.bag as db
from distributed import Client, LocalCluster
import spinal

# the full run: N_CURVES = 100_000, N_FRAMES = 1_000 (see docs/scale-out.md)
N_CURVES, CHUNKS = 8_000, 4
N_FRAMES = 60
cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                       dashboard_address=None, silence_logs=50)
client = Client(cluster)
print(f"{len(client.scheduler_info()['workers'])} worker processes, 1 thread each")""",
    """md:## A bundle of streamline tubes

A synthetic bundle: helical streamlines of a vortex (radius 0.2–2, turning faster near the
axis), 48 points each, made from a seed inside the task. `spinal.tube` turns a chunk of
curves into one mesh (`lengths=`); the task returns a digest of the mesh, its size and
volume and its own compute time. (At scale a task would write its mesh to storage.)""",
    """def bundle(seed, n_curves, n_points=48):
    \"\"\"n_curves helical streamlines from a seed: flat points and lengths.\"\"\"
    rng = np.random.default_rng(seed)
    r = rng.uniform(0.2, 2.0, (n_curves, 1))
    phase = rng.uniform(0, 2 * np.pi, (n_curves, 1))
    z0 = rng.uniform(-1, 1, (n_curves, 1))
    s = np.linspace(0, 1, n_points)
    angle = phase + 2.0 * s / np.sqrt(r)
    points = np.stack([r * np.cos(angle), r * np.sin(angle), z0 + 0.8 * s + 0 * r], axis=-1)
    return points.reshape(-1, 3), np.full(n_curves, n_points)

def digest(*arrays):
    h = hashlib.sha256()
    for a in arrays:
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()[:16]

def tube_chunk(seeds, n_curves):
    \"\"\"One task: the tubes of the curves made from `seeds`, on one thread.\"\"\"
    with spinal.threads(1):
        clock = time.perf_counter()
        points, lengths = zip(*(bundle(s, n_curves) for s in seeds))
        mesh = spinal.tube(np.concatenate(points), 0.004, sides=6, lengths=np.concatenate(lengths))
        seconds = time.perf_counter() - clock
    return {"curves": n_curves * len(seeds), "vertices": len(mesh.vertices),
            "faces": len(mesh.faces), "volume": mesh.volume,
            "digest": digest(mesh.vertices, mesh.faces), "seconds": seconds}

per_seed = 500                                          # curves made from one seed
seeds = np.arange(N_CURVES // per_seed)
chunks = np.array_split(seeds, CHUNKS)
clock = time.perf_counter()
results = db.from_sequence([(c.tolist(), per_seed) for c in chunks], npartitions=CHUNKS) \\
            .starmap(tube_chunk).compute()
wall = time.perf_counter() - clock
for k, r in enumerate(results):
    print(f"chunk {k}: {r['curves']:,} curves, {r['vertices']:,} vertices, "
          f"{r['curves'] / r['seconds']:,.0f} curves/s on one thread, digest {r['digest']}")
print(f"{N_CURVES:,} curves in {wall:.1f} s wall on {len(client.scheduler_info()['workers'])} workers")""",
    """md:### The same as one call

The whole bundle in one call of `spinal.tube` (all threads of this process): every chunk's
slice of the big mesh has the chunk's digest, so the chunks are exactly the single call.""",
    """points, lengths = zip(*(bundle(s, per_seed) for s in seeds))
clock = time.perf_counter()
mesh = spinal.tube(np.concatenate(points), 0.004, sides=6, lengths=np.concatenate(lengths))
single = time.perf_counter() - clock
v0 = f0 = 0
for r in results:
    nv, nf = r["vertices"], r["faces"]
    assert digest(mesh.vertices[v0:v0 + nv], mesh.faces[f0:f0 + nf] - v0) == r["digest"]
    v0, f0 = v0 + nv, f0 + nf
assert v0 == len(mesh.vertices) and f0 == len(mesh.faces)
assert np.isclose(sum(r["volume"] for r in results), mesh.volume, rtol=1e-12)
print(f"single call: {single:.2f} s with {spinal.get_num_threads()} threads; every chunk equal")""",
    """md:## A deformation animation

A tool pushes into a ring-shaped tube; the animation is `N_FRAMES` frames, each advancing the
previous one by `dt` (4 RK4 steps). Advection moves every vertex on its own, so the
vertices split into chunks: a task runs the whole animation on its slice (the field travels
pickled) and returns a digest of its frames and the last frame. Concatenated, the chunks
equal the single call on the whole mesh, frame by frame.""",
    """t = 2 * np.pi * np.arange(256) / 256
ring = spinal.tube(np.c_[np.cos(t), np.sin(t), 0 * t], 0.25, sides=64, closed=True)
tool = spinal.fields.translation([1.6, 0, 0], 0.3, [-0.5, 0, 0])   # a dent 0.15 deep
dt = 0.4 / N_FRAMES

def animate(V, n_frames, chunks=None):
    \"\"\"Frame by frame; a digest of every chunk's rows over all frames, and the last frame.\"\"\"
    hashes = [hashlib.sha256() for _ in (chunks or [slice(None)])]
    for k in range(n_frames):
        V = spinal.advect(V, tool, dt, steps=4, t0=k * dt)
        for h, part in zip(hashes, chunks or [slice(None)]):
            h.update(V[part].tobytes())
    return [h.hexdigest()[:16] for h in hashes], V

@dask.delayed
def animate_chunk(V):
    with spinal.threads(1):
        clock = time.perf_counter()
        (h,), last = animate(V, N_FRAMES)
        return h, last, time.perf_counter() - clock

parts = np.array_split(np.arange(len(ring.vertices)), CHUNKS)
clock = time.perf_counter()
out = dask.compute(*[animate_chunk(ring.vertices[p]) for p in parts])
wall = time.perf_counter() - clock
for p, (h, last, seconds) in zip(parts, out):
    print(f"{len(p):,} vertices x {N_FRAMES} frames: {len(p) * N_FRAMES * 4 / seconds / 1e6:.1f} "
          f"M vertex-steps/s on one thread, digest {h}")
print(f"{N_FRAMES} frames of {len(ring.vertices):,} vertices in {wall:.1f} s wall")""",
    """clock = time.perf_counter()
hashes, last = animate(ring.vertices, N_FRAMES, chunks=[slice(p[0], p[-1] + 1) for p in parts])
single = time.perf_counter() - clock
assert hashes == [h for h, _, _ in out]
assert np.array_equal(last, np.concatenate([l for _, l, _ in out]))
change = spinal.Mesh(last, ring.faces).volume / ring.volume - 1
print(f"single call: {single:.1f} s with {spinal.get_num_threads()} threads; every frame equal; "
      f"volume change after the last frame {change:+.1e}")""",
    """pv_ok = True
try:
    import pyvista as pv
    pv.OFF_SCREEN = True
    pv.set_jupyter_backend("static")
except ImportError:                      # pictures need spinal[viz]
    pv_ok = False
if pv_ok:
    pl = pv.Plotter(window_size=(560, 360))
    pl.add_mesh(spinal.Mesh(last, ring.faces).to_pyvista(), color="#d9a066", smooth_shading=True)
    pl.add_mesh(pv.Sphere(radius=0.3, center=(1.6 - 0.4 * 0.5, 0, 0)), color="#4060a0", opacity=0.3)
    pl.camera_position = [(3.0, -2.4, 2.2), (0.5, 0, 0), (0, 0, 1)]
    pl.show()""",
    """client.close()
cluster.close()""",
    """md:## Scaling up and out

* Larger jobs: set `N_CURVES = 100_000` and `N_FRAMES = 1_000` (and more `CHUNKS`, a few per
  worker). The measured full runs are in `docs/scale-out.md`.
* More machines: replace the `LocalCluster` with a cluster object of
  [dask-jobqueue](https://jobqueue.dask.org/) (`SLURMCluster`, `PBSCluster`, …) or
  [dask-kubernetes](https://kubernetes.dask.org/) and call `cluster.scale(...)`; the task
  functions and the `compute` calls stay the same. Every worker needs spinal installed (the
  same environment or container image).
* At scale, let a task write its mesh or frames to shared storage and return only a small
  summary, as here.""",
])

BOOKS = {"01_frames": frames, "02_tubes": tubes, "03_knot_tube": knot,
         "04_deformation": deform, "05_fleshing": flesh, "06_quaternion_frames": quat,
         "07_scale_out": scale}



def steering_frames():
    """Notebook 08: frames steered by a guide (a protein-like ribbon) and frames coherent in
    time (an animated tube that does not flicker)."""
    return nb([
        """md:# Steering frames: guides, constraints and time

The rotation-minimising frame (RMF) fixes the roll of a frame up to one constant turn. `spinal.frames` can
steer that roll: `constraints=` pins the frame at any rows (the twist in between spread by `twist_rule`),
`guide=` lets `r` follow a direction field (a chemical bond, "up"), smoothed by `guide_weight`, and
`previous=` / `spinal.frames_in_time` keep the frames of a moving curve from jumping between time steps.""",
        SETUP + """
import matplotlib.pyplot as plt
from scipy.interpolate import CubicSpline""",
        """md:## A ribbon that follows the C=O direction

A protein-like Cα trace: a helix of 14 residues, then a pleated strand. Each residue has a "carbonyl"
direction (outward on the helix, alternating across the strand, with noise). As ribbon programs do,
alternate guides are flipped so that consecutive ones agree. The ribbon's `r` follows the guide on a
smooth spline through the trace; the plain RMF does not. `guide_weight` sets the balance: the frame
follows the guide on features longer than about `1/√guide_weight` samples (here 8 samples per residue).""",
        """k = np.arange(14)
helix = np.c_[2.3 * np.cos(np.radians(100) * k), 2.3 * np.sin(np.radians(100) * k), 1.5 * k]
outward = np.c_[np.cos(np.radians(100) * k), np.sin(np.radians(100) * k), 0 * k]
j = np.arange(1, 13)
strand = helix[-1] + np.c_[3.3 * j, 0.9 * (-1.0) ** j, 0.4 * j]
ca = np.r_[helix, strand]
rng = np.random.default_rng(1)
carbonyl = np.r_[outward, np.c_[0 * j, (-1.0) ** j, 0.3 + 0 * j]]
carbonyl = carbonyl + 0.15 * rng.standard_normal(carbonyl.shape)
for i in range(1, len(carbonyl)):  # flip alternate guides
    if carbonyl[i] @ carbonyl[i - 1] < 0:
        carbonyl[i] = -carbonyl[i]

res = np.arange(len(ca))
fine = np.linspace(0, len(ca) - 1, 8 * (len(ca) - 1) + 1)
x = CubicSpline(res, ca)(fine)
guide = np.stack([np.interp(fine, res, carbonyl[:, d]) for d in range(3)], axis=1)
F_guide = spinal.frames(x, guide=guide, guide_weight=2.0)
F_rmf = spinal.frames(x)

def off_guide(F, g):  # angle (degrees) between r and the guide's normal-plane part
    t = F[:, :, 2]
    p = g - np.einsum("ij,ij->i", g, t)[:, None] * t
    p /= np.linalg.norm(p, axis=1)[:, None]
    return np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", F[:, :, 0], p), -1, 1)))

print("r off the guide: median %.2f°, max %.1f° (RMF: median %.0f°)" % (
    np.median(off_guide(F_guide, guide)), off_guide(F_guide, guide).max(),
    np.median(off_guide(F_rmf, guide))))
assert np.median(off_guide(F_guide, guide)) < 3 and off_guide(F_guide, guide).max() < 20""",
        """ribbon = np.array([[0.0, -0.9], [0.0, 0.9]])  # across s: the ribbon's face is normal to r
pl = pv.Plotter(shape=(1, 2), window_size=(900, 380))
for col, (F, title) in enumerate([(F_rmf, "RMF"), (F_guide, "guide = C=O")]):
    pl.subplot(0, col)
    mesh = spinal.sweep(x, ribbon, frames=F, profile_closed=False).to_pyvista()
    pl.add_mesh(mesh, color="#d08c60" if col else "#8aa0b8", smooth_shading=True)
    pl.add_arrows(ca, carbonyl / np.linalg.norm(carbonyl, axis=1)[:, None], mag=1.2,
                  color="#444444")
    pl.add_text(title, font_size=10)
    pl.view_vector((1.0, -1.0, 0.6))
    pl.camera.zoom(1.3)
pl.show()""",
        """md:## Interior constraints and the two twist rules

Pin the frame at three rows; between them the extra twist is spread linearly in arc length (least
∫|ω|² ds, the default) or in proportion to the curvature (least ∫|ω| ds, Zheng eq. 7.5–7.7), which puts
the twist where the curve bends.""",
        """pins = {0: F_rmf[0, :, 0], 60: F_rmf[60, :, 1], len(x) - 1: -F_rmf[-1, :, 0]}
fig, ax = plt.subplots(figsize=(6, 3))
for rule in ("arc_length", "min_angular_speed"):
    F = spinal.frames(x, constraints=pins, twist_rule=rule)
    twist = np.unwrap(np.arctan2(np.einsum("ij,ij->i", F[:, :, 0], F_rmf[:, :, 1]),
                                 np.einsum("ij,ij->i", F[:, :, 0], F_rmf[:, :, 0])))
    ax.plot(fine, twist, label=rule)
    for row, v in pins.items():
        assert np.abs(F[row, :, 0] - v).max() < 1e-12
ax.set_xlabel("residue"); ax.set_ylabel("twist from the RMF (rad)"); ax.legend()""",
        """md:## A tube that does not flicker

A curve waves through a straight position. Started afresh at every time step, its frames depend on the
principal normal near the start, which turns over when the curve straightens: the tube's stripes jump by
half a turn. `spinal.frames_in_time` follows the step before sample by sample (each frame turns by about
as much as its tangent); `previous_twist=False` turns each step's RMF by the one angle closest to the step
before instead.""",
        """T = 8
xs = np.linspace(0, 6, 120)
P = np.array([np.c_[xs, a * np.sin(xs), 0.5 * a * np.cos(1.3 * xs) + 0.1 * xs]
              for a in np.linspace(0.8, -0.8, T)])
afresh = np.array([spinal.frames(p) for p in P])
coherent = spinal.frames_in_time(P)

def largest_change(F):  # degrees, per time step, over the samples
    tr = np.einsum("knij,knij->kn", F[1:], F[:-1])
    return np.degrees(np.arccos(np.clip((tr - 1) / 2, -1, 1))).max(axis=1)

tangent = np.degrees(np.arccos(np.clip(
    np.einsum("kni,kni->kn", coherent[1:, :, :, 2], coherent[:-1, :, :, 2]), -1, 1))).max(axis=1)
print("largest frame change per step, afresh:    ", largest_change(afresh).round(1))
print("largest frame change per step, coherent:  ", largest_change(coherent).round(1))
print("largest tangent change per step:          ", tangent.round(1))
assert largest_change(afresh).max() > 90 and largest_change(coherent).max() < 20""",
        """stripes = np.array([[np.cos(a), np.sin(a)] for a in np.linspace(0, 2 * np.pi, 12,
                                                                         endpoint=False)]) * 0.35
pl = pv.Plotter(shape=(1, 2), window_size=(900, 420))
for row, (F, title) in enumerate([(afresh, "started afresh"), (coherent, "frames_in_time")]):
    pl.subplot(0, row)
    for k in (2, 3, 4, 5):
        mesh = spinal.sweep(P[k] + [0, 0, 2.0 * k], stripes, frames=F[k], caps=False)
        mesh = mesh.to_pyvista()  # ring i holds vertices 12 i … 12 i + 11
        mesh["side"] = np.tile(np.arange(12) < 4, len(xs)).astype(float)
        pl.add_mesh(mesh, scalars="side", cmap=["#e8e0d0", "#b04a3a"], show_scalar_bar=False,
                    smooth_shading=True)
    pl.add_text(title, font_size=10)
    pl.view_vector((0.35, -1.0, 0.45))
    pl.camera.zoom(1.3)
pl.show()""",
    ])


BOOKS["08_steering_frames"] = steering_frames()


def write(name: str, book, folder: str = "notebooks") -> str:
    """Write one notebook with stable cell ids (``<topic>-<index>``), so that regenerating
    an unchanged notebook gives an unchanged file."""
    topic = name.split("_", 1)[1].replace("_", "-")
    for i, cell in enumerate(book.cells):
        cell["id"] = f"{topic}-{i:02d}"
    path = f"{folder}/{name}.ipynb"
    nbf.write(book, path)
    return path


def small_png(data: str, colors: int = 256) -> str:
    """A base64 PNG re-encoded with an adaptive palette (a few times smaller for renders and
    plots, no visible change), or the input when that is not smaller."""
    from PIL import Image

    image = Image.open(io.BytesIO(base64.b64decode(data)))
    buf = io.BytesIO()
    image.convert("RGB").quantize(colors, method=Image.Quantize.MEDIANCUT).save(
        buf, format="PNG", optimize=True)
    small = base64.b64encode(buf.getvalue()).decode("ascii")
    return small if len(small) < len(data) else data


def tidy(book) -> None:
    """Outputs as stored: no stderr streams (progress lines, warnings), pictures as small
    palette PNGs, no execution timing metadata."""
    for cell in book.cells:
        if cell.cell_type != "code":
            continue
        cell.metadata.pop("execution", None)
        kept = []
        for out in cell.outputs:
            if out.output_type == "stream" and out.name == "stderr":
                continue
            data = out.get("data", {})
            if "image/png" in data:
                data["image/png"] = small_png(data["image/png"])
            kept.append(out)
        cell.outputs = kept


def execute(path: str, timeout: int = 1800) -> None:
    """Run the notebook at ``path`` in a fresh kernel (in its folder, pyvista off-screen) and
    store its tidied outputs."""
    import nbclient

    os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")
    os.environ["MPLBACKEND"] = "module://matplotlib_inline.backend_inline"  # figures inline
    if sys.platform.startswith("linux") and not (os.environ.get("DISPLAY")
                                                 or os.environ.get("WAYLAND_DISPLAY")):
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    book = nbf.read(path, as_version=4)
    client = nbclient.NotebookClient(book, timeout=timeout, kernel_name="python3",
                                     record_timing=False,
                                     resources={"metadata": {"path": str(pathlib.Path(path).parent)}})
    client.execute()
    tidy(book)
    nbf.write(book, path)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("names", nargs="*", help="notebooks to write (name or number; default all)")
    ap.add_argument("--no-execute", action="store_true", help="write cells without outputs")
    a = ap.parse_args(argv)
    chosen = [n for n in BOOKS if not a.names or any(n == k or n.split("_")[0] == k.zfill(2)
                                                     for k in a.names)]
    for name in chosen:
        path = write(name, BOOKS[name])
        if not a.no_execute:
            execute(path)
        print("wrote", path, "" if a.no_execute else "(executed)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
