"""Write the gallery notebooks (source of truth for their cells); run from the repo root:
``python tools/make_notebooks.py``. The test suite executes the notebooks (nbmake)."""

from __future__ import annotations

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
    """poly = mesh.to_pyvista()
poly["speed"] = np.repeat(speed, 10)
pl = pv.Plotter(window_size=(640, 480))
pl.add_mesh(poly, scalars="speed", cmap="magma", smooth_shading=True, show_scalar_bar=False)
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
i = 120
pl.camera.position = knot[i] + 0.05 * cam[i][:, 1]
pl.camera.focal_point = knot[i] - cam[i][:, 2]
pl.camera.up = cam[i][:, 1]
pl.show()""",
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

if __name__ == "__main__":
    for name, book in [("02_tubes", tubes), ("03_knot_tube", knot), ("06_quaternion_frames", quat)]:
        nbf.write(book, f"notebooks/{name}.ipynb")
        print("wrote", f"notebooks/{name}.ipynb")
