//! Spine surfaces given as triangle meshes (Zhuo 2014 Ch. VI and §7.2): a shape bound to a
//! triangulated surface keeps its volume when the surface's vertices move.
//!
//! **Model.** Vertices `S_i`, faces `(a, b, c)`; the normal side is the one the faces'
//! winding gives (`(S_b − S_a) × (S_c − S_a)`). The vertex normals `n_i` are the unit
//! angle-weighted sums of the face normals (Thürmer & Wüthrich 1998). In face `f` with the
//! barycentric coordinates `(1 − u − v, u, v)` the surface is the flat triangle
//! `S = S_a + u (S_b − S_a) + v (S_c − S_a)` and the normal is the interpolated vertex normal
//! `N = M/|M|`, `M = (1 − u − v) n_a + u n_b + v n_c` (as §7.2 interpolates normals with the
//! barycentrics; Phong's normal). A point is `P = S(u, v) + h N(u, v)` (Assumption II).
//!
//! **Volume element.** `S_u = S_b − S_a`, `S_v = S_c − S_a` are constant in the face and
//! `N_u = (I − N Nᵀ)(n_b − n_a)/|M|`, `N_v = (I − N Nᵀ)(n_c − n_a)/|M|`, so
//! `det ∂P/∂(u, v, h) = det[S_u + hN_u, S_v + hN_v, N] = A + B h + C h²` with
//! `A = (S_u × S_v)·N`, `B = (S_u × N_v + N_u × S_v)·N`, `C = (N_u × N_v)·N` — the same form
//! as on a smooth surface (Eq. 38: `A = σ`, `B = −2mσ`, `C = gσ`), where the mean and Gaussian
//! curvature `m = −B/(2A)`, `g = C/A` are those of the interpolated normal field: the faces
//! are flat, all the bending is in the normals. So `det ∂P1/∂P0 = 1` requires, at every
//! `(u, v)` of the face, `A1 h1 + B1 h1²/2 + C1 h1³/3 = A0 h0 + B0 h0²/2 + C0 h0³/3` with the
//! face's own `A, B, C` at `(u, v)` (Eq. 40–43), solved with the fold-free root rule of the
//! grid model ([`super::surface::surface_offset`]). Interpolating vertex estimates of `m`, `g`
//! and of the area stretch with the barycentrics (§7.2) would not give determinant 1.
//!
//! **Seams.** `S` and `N` are continuous across an edge (there both faces interpolate the
//! edge's two vertices only), but `A, B, C` are derivatives and jump across edges, so the
//! corrected offset, and the map, jump across the boundaries of the faces' normal prisms —
//! except where the pose is the identity or, for a flat surface, an affine map of its plane
//! (then `B = C = 0` and `A1/A0` is constant). On a smooth surface the jump is first order
//! in the edge length (measured on a bent and stretched plate, offsets up to 0.3:
//! 5.4e-3, 1.9e-3, 8.5e-4 for edges of 0.2, 0.1, 0.05); a closed shape that crosses seams
//! gains or loses the slivers between them (a discretisation error of the piecewise-linear
//! surface; the grid model's C¹ bicubic cells have none).
//!
//! **Given directions.** The posed offset may be laid along directions given per vertex
//! ([`TriSurface::with_directions`]: a rig's frames, a constant "up") instead of the vertex
//! normals, interpolated the same way; the volume element keeps its form with `D` for `N`,
//! so the same correction keeps the volume. [`TriSurface::frames`] gives the frames at the
//! vertices (the vertex normal and the projected `S_u` edge of the vertex's first face).
//!
//! **Registration.** The closest point of the triangle mesh (branch and bound over the
//! faces' boxes in a bounding-volume hierarchy, [`crate::math::bvh`]; exact point–triangle
//! distance by Voronoi regions, Ericson, Real-Time Collision Detection §5.1.5), then the foot
//! of the normal segment, `S(u, v) + h N(u, v) = P` solved by Newton's method in the faces
//! sharing a vertex with the closest face (then one ring further): the smallest `|h|` inside
//! a face wins (ties: the lowest face). Without one the point is attached at its closest
//! point with its residual carried rigidly in the local frame (not volume preserving;
//! reported), as the grid model does past its border.

use glam::DVec3;
use rayon::prelude::*;

use super::surface::{Bound, SURFACE_COORDS, SurfLocal, check_sizes, deform_bound, newton_foot};
use crate::error::{InputError, Result};
use crate::math::bvh::{Aabb, Bvh};
use crate::math::scale::{self, Pow2};
use crate::run::alloc;
use crate::run::cancel::Cancel;

/// A triangulated spine surface (model units, see [`super::surface::Surface::scale`]).
#[derive(Clone, Debug)]
pub struct TriSurface {
    /// Input units to model units.
    pub scale: Pow2,
    /// Vertices (model units).
    pub s: Vec<DVec3>,
    /// Unit angle-weighted vertex normals (zero at vertices no face uses).
    pub n: Vec<DVec3>,
    /// Faces.
    pub faces: Vec<[usize; 3]>,
}

impl TriSurface {
    /// The surface of `points` and `faces` (row-major triples); errors name `arg`
    /// (`"rest_surface"` or `"posed_surface"`).
    pub fn new(arg: &'static str, points: &[DVec3], faces: &[i64]) -> Result<TriSurface> {
        let call = if arg == "rest_surface" {
            "SurfaceBinding"
        } else {
            "SurfaceBinding.deform"
        };
        if faces.is_empty() || faces.len() % 3 != 0 {
            return Err(InputError::new(arg, "need at least one triangle (F, 3)"));
        }
        if let Some(i) = points.iter().position(|p| !p.is_finite()) {
            return Err(InputError::new(arg, format!("vertex {i} is not finite")));
        }
        let nv = points.len();
        let mut fs: Vec<[usize; 3]> = alloc::with_capacity(call, faces.len() / 3)?;
        for (k, f) in faces.chunks_exact(3).enumerate() {
            if let Some(&i) = f.iter().find(|&&i| i < 0 || i as usize >= nv) {
                return Err(InputError::new(
                    arg,
                    format!("face {k} refers to vertex {i}, but there are {nv} vertices"),
                ));
            }
            let t = [f[0] as usize, f[1] as usize, f[2] as usize];
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                return Err(InputError::new(
                    arg,
                    format!("face {k} repeats a vertex ({}, {}, {})", t[0], t[1], t[2]),
                ));
            }
            fs.push(t);
        }
        let (lo, hi) = crate::frames::geometry::bounds(points);
        let k = scale::curve_exponent(lo, hi).unwrap_or(0);
        let s = if k == 0 {
            alloc::copied(call, points)?
        } else {
            scale::try_scaled(call, points, k)?
        };
        // angle-weighted vertex normals
        let mut n = alloc::filled(call, nv, DVec3::ZERO)?;
        for (k, t) in fs.iter().enumerate() {
            let c = (s[t[1]] - s[t[0]]).cross(s[t[2]] - s[t[0]]);
            let (l, e) = (c.length(), (s[t[1]] - s[t[0]]).length());
            let e2 = (s[t[2]] - s[t[0]]).length();
            if !(l > 1e-300) || !(l > 1e-12 * e * e2) {
                return Err(InputError::new(
                    arg,
                    format!("face {k} is degenerate (its vertices are on a line)"),
                ));
            }
            let fnorm = c / l;
            for j in 0..3 {
                let (a, b) = (s[t[(j + 1) % 3]] - s[t[j]], s[t[(j + 2) % 3]] - s[t[j]]);
                let angle = a.cross(b).length().atan2(a.dot(b));
                n[t[j]] += angle * fnorm;
            }
        }
        for (i, m) in n.iter_mut().enumerate() {
            if *m == DVec3::ZERO {
                continue; // no face: never evaluated
            }
            let l = m.length();
            if !(l > 1e-6) {
                return Err(InputError::new(
                    arg,
                    format!(
                        "vertex {i}: the normals of its faces cancel (faces of opposite \
                         orientation)"
                    ),
                ));
            }
            *m /= l;
        }
        // A = |S_u × S_v| n_f·M/|M| > 0 over a face iff n_f·n_i > 0 at its corners
        for (k, t) in fs.iter().enumerate() {
            let nf = (s[t[1]] - s[t[0]]).cross(s[t[2]] - s[t[0]]).normalize();
            if let Some(&i) = t.iter().find(|&&i| !(nf.dot(n[i]) > 0.0)) {
                return Err(InputError::new(
                    arg,
                    format!(
                        "face {k}: the normal of vertex {i} is on the other side of the face \
                         (the surface folds over there)"
                    ),
                ));
            }
        }
        Ok(TriSurface {
            scale: Pow2::new(k),
            s,
            n,
            faces: fs,
        })
    }

    /// The surface with the offset laid along the given directions `dirs` (one per vertex,
    /// named `dir_arg`, made unit) instead of the vertex normals, interpolated over the faces
    /// exactly as the normals are (barycentric, then made unit). The volume element
    /// `det[S_u + hD_u, S_v + hD_v, D]` and so the offset correction hold for any unit
    /// direction field `D` transverse to the faces. A direction at 1e-3 or less in cosine
    /// from its vertex normal is refused, and so is a face whose corner direction is not on
    /// its side (`n_f·D > 0` over the face iff it holds at the corners, the interpolation
    /// being linear before the normalisation).
    pub fn with_directions(
        arg: &'static str,
        points: &[DVec3],
        faces: &[i64],
        dir_arg: &'static str,
        dirs: &[DVec3],
    ) -> Result<TriSurface> {
        let mut sf = TriSurface::new(arg, points, faces)?;
        if dirs.len() != sf.s.len() {
            return Err(InputError::new(
                dir_arg,
                format!(
                    "expected {} directions like the surface's vertices, got {}",
                    sf.s.len(),
                    dirs.len()
                ),
            ));
        }
        let mut d = alloc::with_capacity("SurfaceBinding.deform", dirs.len())?;
        for (i, (&g, &normal)) in dirs.iter().zip(&sf.n).enumerate() {
            let Some(g) = scale::normalize(g) else {
                return Err(InputError::new(
                    dir_arg,
                    format!("vertex {i}: not a finite non-zero vector"),
                ));
            };
            let c = g.dot(normal);
            if normal != DVec3::ZERO && !(c > 1e-3) {
                return Err(InputError::new(
                    dir_arg,
                    format!(
                        "vertex {i}: the direction is {:.1}° from the surface normal: \
                         parallel to the surface or on its other side",
                        c.clamp(-1.0, 1.0).acos().to_degrees()
                    ),
                ));
            }
            d.push(g);
        }
        for (k, t) in sf.faces.iter().enumerate() {
            let nf = (sf.s[t[1]] - sf.s[t[0]]).cross(sf.s[t[2]] - sf.s[t[0]]);
            if let Some(&i) = t.iter().find(|&&i| !(nf.dot(d[i]) > 0.0)) {
                return Err(InputError::new(
                    dir_arg,
                    format!(
                        "face {k}: the direction of vertex {i} is not on the face's normal \
                         side, so the interpolated direction reaches the face's plane"
                    ),
                ));
            }
        }
        sf.n = d;
        Ok(sf)
    }

    /// Orthonormal frames `[e1, e2, n]` at the vertices: `n` the vertex normal, `e1` the
    /// first edge `S_b − S_a` (the face's `S_u`) of the lowest-numbered face around the
    /// vertex, projected on the normal plane and made unit, `e2 = n × e1` (the identity at
    /// vertices no face uses). On a grid triangulated with the `S_u` edge first this is the
    /// grid model's frame (`e1` along `S_u`).
    pub fn frames(&self, call: &'static str) -> Result<Vec<[DVec3; 3]>> {
        let mut first = alloc::filled(call, self.s.len(), usize::MAX)?;
        for (k, t) in self.faces.iter().enumerate().rev() {
            for &i in t {
                first[i] = k;
            }
        }
        alloc::collect(
            call,
            first.iter().zip(&self.n).map(|(&k, &n)| {
                if k == usize::MAX {
                    return [DVec3::X, DVec3::Y, DVec3::Z];
                }
                let [a, b, _] = self.faces[k];
                let t = self.s[b] - self.s[a];
                let e1 = (t - n * n.dot(t)).normalize();
                [e1, n.cross(e1), n]
            }),
        )
    }

    /// The surface in face `f` at the barycentric coordinates `(1 − u − v, u, v)`.
    #[inline]
    pub fn eval(&self, f: usize, u: f64, v: f64) -> SurfLocal {
        let [a, b, c] = self.faces[f];
        let (sa, su, sv) = (self.s[a], self.s[b] - self.s[a], self.s[c] - self.s[a]);
        let (na, mu, mv) = (self.n[a], self.n[b] - self.n[a], self.n[c] - self.n[a]);
        let m = na + u * mu + v * mv;
        let ml = m.length();
        let nn = m / ml;
        SurfLocal {
            s: sa + u * su + v * sv,
            su,
            sv,
            n: nn,
            nu: (mu - nn * nn.dot(mu)) / ml,
            nv: (mv - nn * nn.dot(mv)) / ml,
        }
    }

    fn corners(&self, f: usize) -> [DVec3; 3] {
        self.faces[f].map(|i| self.s[i])
    }
}

/// The closest point of triangle `t` to `p` as barycentric `(u, v)` (weights of the second
/// and third corners) and its squared distance (Ericson 2005, §5.1.5).
fn closest_on_triangle(p: DVec3, t: &[DVec3; 3]) -> (f64, f64, f64) {
    let (a, b, c) = (t[0], t[1], t[2]);
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    let uv = if d1 <= 0.0 && d2 <= 0.0 {
        (0.0, 0.0)
    } else {
        let bp = p - b;
        let (d3, d4) = (ab.dot(bp), ac.dot(bp));
        let cp = p - c;
        let (d5, d6) = (ab.dot(cp), ac.dot(cp));
        let vc = d1 * d4 - d3 * d2;
        let vb = d5 * d2 - d1 * d6;
        let va = d3 * d6 - d5 * d4;
        if d3 >= 0.0 && d4 <= d3 {
            (1.0, 0.0)
        } else if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
            (d1 / (d1 - d3), 0.0)
        } else if d6 >= 0.0 && d5 <= d6 {
            (0.0, 1.0)
        } else if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
            (0.0, d2 / (d2 - d6))
        } else if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
            let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
            (1.0 - w, w)
        } else {
            let den = 1.0 / (va + vb + vc);
            (vb * den, vc * den)
        }
    };
    let q = a + uv.0 * ab + uv.1 * ac;
    (uv.0, uv.1, (p - q).length_squared())
}

/// Faces around every vertex (compressed rows: `start[i]..start[i + 1]` in `list`).
struct Around {
    start: Vec<usize>,
    list: Vec<usize>,
}

fn around(call: &'static str, nv: usize, faces: &[[usize; 3]]) -> Result<Around> {
    let mut start = alloc::filled(call, nv + 1, 0usize)?;
    for t in faces {
        for &i in t {
            start[i + 1] += 1;
        }
    }
    for i in 0..nv {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut list = alloc::filled(call, 3 * faces.len(), 0usize)?;
    for (k, t) in faces.iter().enumerate() {
        for &i in t {
            list[fill[i]] = k;
            fill[i] += 1;
        }
    }
    Ok(Around { start, list })
}

/// `(|h|, face, u, v, h)` of a foot point.
type Foot = (f64, usize, f64, f64, f64);

/// The foot of `p` in face `f` if it lies inside the face (round-off allowed).
fn try_face(sf: &TriSurface, f: usize, p: DVec3, best: &mut Option<Foot>) {
    let Some((u, v, h)) = newton_foot(|u, v| sf.eval(f, u, v), (1.0 / 3.0, 1.0 / 3.0), p) else {
        return;
    };
    let tol = 1e-9;
    if u >= -tol && v >= -tol && u + v <= 1.0 + tol {
        let better = match best {
            None => true,
            Some(b) => h.abs() < b.0 || (h.abs() == b.0 && f < b.1),
        };
        if better {
            let (u, v) = (u.max(0.0), v.max(0.0));
            let s = u + v;
            let (u, v) = if s > 1.0 { (u / s, v / s) } else { (u, v) };
            *best = Some((h.abs(), f, u, v, h));
        }
    }
}

/// Register `vertices` on the rest triangle surface: the face and [`SURFACE_COORDS`] numbers
/// per vertex (`[u, v, h0, A0, B0, C0, r1, r2, r3]`, as the grid model stores them).
pub fn bind_trisurface(
    rest: &TriSurface,
    vertices: &[DVec3],
    cancel: Cancel<'_>,
) -> Result<(Vec<i64>, Vec<f64>)> {
    super::check_vertices(vertices, rest.scale, "surface")?;
    let (to_model, to_input) = (rest.scale, rest.scale.inverse());
    let call = "SurfaceBinding";
    let nv = vertices.len();
    let boxes = alloc::collect(
        call,
        (0..rest.faces.len()).map(|f| Aabb::of_points(&rest.corners(f))),
    )?;
    let bvh = Bvh::build(&boxes);
    let ring = around(call, rest.s.len(), &rest.faces)?;
    let mut face = alloc::filled(call, nv, 0i64)?;
    let mut coords = alloc::filled(call, alloc::product(call, SURFACE_COORDS, nv, 8)?, 0.0)?;
    face.par_iter_mut()
        .zip(coords.par_chunks_mut(SURFACE_COORDS))
        .zip(vertices.par_iter())
        .for_each_init(Vec::new, |stack, ((fo, out), &p)| {
            if cancel() {
                return;
            }
            let p = to_model.of3(p);
            // the closest face (ties: the lowest index)
            let mut near = (f64::INFINITY, usize::MAX, 0.0, 0.0);
            bvh.nearest(p, f64::INFINITY, stack, |f| {
                let (u, v, d) = closest_on_triangle(p, &rest.corners(f));
                if d < near.0 || (d == near.0 && f < near.1) {
                    near = (d, f, u, v);
                }
                near.0
            });
            let f0 = near.1;
            // the faces sharing a vertex with it, then one ring further
            let mut cand: Vec<usize> = rest.faces[f0]
                .iter()
                .flat_map(|&i| ring.list[ring.start[i]..ring.start[i + 1]].iter().copied())
                .collect();
            cand.sort_unstable();
            cand.dedup();
            let mut best: Option<Foot> = None;
            for &f in &cand {
                try_face(rest, f, p, &mut best);
            }
            if best.is_none() {
                let mut more: Vec<usize> = cand
                    .iter()
                    .flat_map(|&g| rest.faces[g])
                    .flat_map(|i| ring.list[ring.start[i]..ring.start[i + 1]].iter().copied())
                    .filter(|g| cand.binary_search(g).is_err())
                    .collect();
                more.sort_unstable();
                more.dedup();
                for &f in &more {
                    try_face(rest, f, p, &mut best);
                }
            }
            let (f, u, v, h, resid) = match best {
                Some((_, f, u, v, h)) => (f, u, v, h, DVec3::ZERO),
                None => {
                    // outside: attached at the closest point, residual in the local frame
                    let (u, v) = (near.2, near.3);
                    let l = rest.eval(f0, u, v);
                    let (e1, e2) = l.frame();
                    let d = p - l.s;
                    (f0, u, v, 0.0, DVec3::new(d.dot(e1), d.dot(e2), d.dot(l.n)))
                }
            };
            let l = rest.eval(f, u, v);
            let (a, b, cc) = l.abc();
            let (h, resid) = (to_input.of(h), to_input.of3(resid));
            *fo = f as i64;
            out.copy_from_slice(&[u, v, h, a, b, cc, resid.x, resid.y, resid.z]);
        });
    Ok((face, coords))
}

/// Deform vertices registered on a triangle surface onto the posed one (same faces);
/// `rest_exp` is the exponent of the rest surface's scale.
#[allow(clippy::too_many_arguments)]
pub fn deform_trisurface(
    posed: &TriSurface,
    rest_exp: i32,
    face: &[i64],
    coords: &[f64],
    corrected: bool,
    out: &mut [DVec3],
    flags: &mut [u8],
    cancel: Cancel<'_>,
) -> Result<()> {
    check_sizes(face.len(), coords, out, flags)?;
    let nf = posed.faces.len();
    if let Some(i) = face.iter().position(|&f| f < 0 || f as usize >= nf) {
        return Err(InputError::new(
            "posed_surface",
            format!("vertex {i} is bound to a face the posed surface does not have"),
        ));
    }
    let foot = |f: i64, x: &[f64]| posed.eval(f as usize, x[0], x[1]);
    let vertices = Bound {
        at: face,
        coords,
        corrected,
    };
    deform_bound(posed.scale, rest_exp, vertices, out, flags, cancel, foot)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::cancel;

    /// A bent `n × n` grid triangulated, and a deterministic cloud of points about it.
    fn bent(n: usize) -> (Vec<DVec3>, Vec<i64>) {
        let mut pts = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let (x, y) = (
                    i as f64 / (n - 1) as f64 - 0.5,
                    j as f64 / (n - 1) as f64 - 0.5,
                );
                pts.push(DVec3::new(x, y, 0.4 * x * x - 0.2 * y * y + 0.1 * x * y));
            }
        }
        let mut f = Vec::new();
        for i in 0..n - 1 {
            for j in 0..n - 1 {
                let a = (i * n + j) as i64;
                let (b, c, d) = (a + n as i64, a + 1, a + n as i64 + 1);
                f.extend([a, b, d, a, d, c]);
            }
        }
        (pts, f)
    }

    fn cloud(k: usize) -> Vec<DVec3> {
        (0..k)
            .map(|i| {
                let t = i as f64;
                DVec3::new(
                    0.7 * (0.37 * t).sin(),
                    0.7 * (0.71 * t + 1.0).sin(),
                    0.3 * (1.13 * t).cos(),
                )
            })
            .collect()
    }

    #[test]
    fn closest_point_on_a_triangle_is_the_minimum_over_the_triangle() {
        let t = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.2, 0.1),
            DVec3::new(0.3, 0.9, -0.2),
        ];
        for p in cloud(200).into_iter().map(|p| 2.0 * p) {
            let (u, v, d) = closest_on_triangle(p, &t);
            assert!(u >= 0.0 && v >= 0.0 && u + v <= 1.0 + 1e-15);
            let q = t[0] + u * (t[1] - t[0]) + v * (t[2] - t[0]);
            assert!(((p - q).length_squared() - d).abs() < 1e-14);
            let m = 200;
            for a in 0..=m {
                for b in 0..=m - a {
                    let (a, b) = (a as f64 / m as f64, b as f64 / m as f64);
                    let s = t[0] + a * (t[1] - t[0]) + b * (t[2] - t[0]);
                    assert!((p - s).length_squared() >= d - 1e-14);
                }
            }
        }
    }

    #[test]
    fn feet_rebuild_the_points_and_have_the_smallest_offset() {
        let (pts, f) = bent(12);
        let sf = TriSurface::new("rest_surface", &pts, &f).unwrap();
        let vs: Vec<DVec3> = cloud(300).into_iter().map(|p| p * 0.6).collect();
        let (face, coords) = bind_trisurface(&sf, &vs, &cancel::never).unwrap();
        let mut inside = 0;
        for (k, p) in vs.iter().enumerate() {
            let c = &coords[SURFACE_COORDS * k..SURFACE_COORDS * (k + 1)];
            if c[6..9] != [0.0; 3] {
                continue; // outside the surface
            }
            inside += 1;
            let l = sf.eval(face[k] as usize, c[0], c[1]);
            assert!((l.s + c[2] * l.n - *p).length() < 1e-12);
            // no face has a foot with a smaller |h| (brute force over all faces)
            let mut best: Option<Foot> = None;
            for g in 0..sf.faces.len() {
                try_face(&sf, g, *p, &mut best);
            }
            let b = best.unwrap();
            assert!(b.0 >= c[2].abs() - 1e-12, "{k}: {} < {}", b.0, c[2].abs());
        }
        assert!(inside > 200, "{inside}");
    }

    #[test]
    fn given_directions_and_frames() {
        // the bent plate: its own normals given back reproduce it; a constant "up" gives
        // A = (S_u × S_v)·z and B = C = 0; the frames are rotations with the vertex normals
        let (pts, f) = bent(6);
        let sf = TriSurface::new("s", &pts, &f).unwrap();
        let same = TriSurface::with_directions("s", &pts, &f, "d", &sf.n).unwrap();
        let (a, b) = (sf.eval(7, 0.3, 0.2), same.eval(7, 0.3, 0.2));
        let (x, y) = (a.abc(), b.abc());
        assert!((a.n - b.n).length() < 1e-15, "{:?}", a.n - b.n);
        assert!((x.0 - y.0).abs() + (x.1 - y.1).abs() + (x.2 - y.2).abs() < 1e-13);
        let up = vec![DVec3::Z * 3.0; pts.len()];
        let l = TriSurface::with_directions("s", &pts, &f, "d", &up)
            .unwrap()
            .eval(11, 0.25, 0.5);
        let (a, b, c) = l.abc();
        let ex = l.su.cross(l.sv).z;
        assert!((a - ex).abs() < 1e-15 && b.abs() < 1e-15 && c.abs() < 1e-15);
        let err = TriSurface::with_directions("s", &pts, &f, "d", &vec![DVec3::NEG_Z; pts.len()])
            .unwrap_err();
        assert!(err.to_string().starts_with("d: vertex 0:"), "{err}");
        for (fr, n) in sf.frames("t").unwrap().iter().zip(&sf.n) {
            assert!(fr[2] == *n && fr[0].dot(*n).abs() < 1e-15);
            assert!((fr[0].cross(fr[1]).dot(fr[2]) - 1.0).abs() < 1e-15);
        }
    }
}
