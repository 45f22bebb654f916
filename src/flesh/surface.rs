//! Spine surfaces (Zhuo 2014 Ch. VI, §6.2): a shape bound to a surface keeps its
//! volume when the surface bends and stretches.
//!
//! Model: the surface is a grid of samples, a bicubic Hermite patch (zero twist, derivatives
//! by central differences) in every cell `(i, j)`, `(u, v) ∈ [0,1]²`; the unit normal
//! `N = m/|m|` with `m` the same bicubic interpolation of the sample normals (central
//! differences `S_u × S_v`) — both C¹ across cell edges, so the map is continuous there. A point is `P = S(u, v) + h N(u, v)` (Assumption II:
//! normal segments stay normal segments). The volume element is exactly
//! `det[S_u + hN_u, S_v + hN_v, N] = A + B h + C h²` with `A = (S_u×S_v)·N`,
//! `B = (S_u×N_v + N_u×S_v)·N`, `C = (N_u×N_v)·N` — in the thesis' notation `A = σ`,
//! `B = −2mσ`, `C = gσ` (Eq. 38) — so the corrected offset solves (Eq. 40–43)
//! `A1 h1 + B1 h1²/2 + C1 h1³/3 = A0 h0 + B0 h0²/2 + C0 h0³/3`, i.e.
//! `F(h1) = h1 − m1 h1² + g1 h1³/3 = (A0 h0 + B0 h0²/2 + C0 h0³/3)/A1`. Root selection: the
//! root on the branch where `F' = (1 − k_a h)(1 − k_b h) > 0`, i.e. below `h_c = 1/k_max`
//! (`F' = 0` there: a critical point of the cubic, which §6.2 calls an inflection point);
//! without one, the largest fold-free offset `h_c` (clamped, reported), as §6.2 prescribes.
//! The validity test printed in §6.2 uses the opposite sign of `m` and lacks a square; we
//! test `F(h_c) ≥ h_t` directly, which is equivalent to the corrected inequality.
//! Points whose foot lies outside the grid are attached to the border with their residual
//! carried rigidly in the local frame (not volume preserving; reported).
//! The posed offset direction may be given per sample instead of the normal
//! ([`Surface::with_directions`]: a rig's frames, a constant "up"): the same interpolation
//! gives a unit field `D`, and `P = S + hD` has the volume element `det[S_u + hD_u, S_v + hD_v, D]`
//! of the same form, so the same correction keeps the volume.

use glam::DVec3;
use rayon::prelude::*;

use super::solve::CLAMPED_BEND;
use crate::error::{InputError, Result};
use crate::math::cubic::basis;
use crate::math::scale::{self, Pow2};
use crate::run::alloc;
use crate::run::cancel::Cancel;

/// Flag: the vertex's foot is outside the surface (attached to the border, uncorrected).
pub const OUTSIDE: u8 = 4;
/// Numbers stored per vertex: `[u, v, h0, A0, B0, C0, r1, r2, r3]` (r: border residual).
/// `h0` and `r` are in the units of the input; `A0` (an area per cell) and `B0` (a length)
/// in the units of the rest surface's model ([`Surface::scale`], whose exponent the binding
/// keeps with the coordinates).
pub const SURFACE_COORDS: usize = 9;

/// A sampled spine surface.
///
/// The model is built on the samples divided by their power-of-two scale
/// ([`scale::curve_exponent`]; "model units", exact): its normals are cross products of
/// differences and its volume element a cubic in the offset, which leave the range of f64
/// for surfaces far from unit size although the input is fine.
#[derive(Clone, Debug)]
pub struct Surface {
    /// Input units to model units (`2^k`, 1 for surfaces of moderate size).
    pub scale: Pow2,
    /// Grid rows (first index `i`).
    pub nu: usize,
    /// Grid columns (second index `j`); sample `(i, j)` is row `i·nv + j`.
    pub nv: usize,
    /// Surface samples `S_ij`, row-major (model units).
    pub s: Vec<DVec3>,
    /// Unit normals at the samples, `S_i × S_j` by central differences.
    pub n: Vec<DVec3>,
    /// Per sample: `[∂S/∂i, ∂S/∂j, ∂n/∂i, ∂n/∂j]` by central differences (per grid step).
    pub d: Vec<[DVec3; 4]>,
}

fn grid_diff(x: &[DVec3], nu: usize, nv: usize, i: usize, j: usize) -> (DVec3, DVec3) {
    let at = |i: usize, j: usize| x[i * nv + j];
    let (i0, i1) = (i.saturating_sub(1), (i + 1).min(nu - 1));
    let (j0, j1) = (j.saturating_sub(1), (j + 1).min(nv - 1));
    (
        (at(i1, j) - at(i0, j)) / (i1 - i0) as f64,
        (at(i, j1) - at(i, j0)) / (j1 - j0) as f64,
    )
}

/// The surface at one point of a cell.
#[derive(Clone, Copy, Debug)]
pub struct SurfLocal {
    /// The point `S(u, v)` (model units).
    pub s: DVec3,
    /// `∂S/∂u` (per grid step).
    pub su: DVec3,
    /// `∂S/∂v` (per grid step).
    pub sv: DVec3,
    /// Unit normal `N(u, v)`.
    pub n: DVec3,
    /// `∂N/∂u` (per grid step; ⟂ N).
    pub nu: DVec3,
    /// `∂N/∂v` (per grid step; ⟂ N).
    pub nv: DVec3,
}

impl SurfLocal {
    /// `(A, B, C)` of the volume element `A + B h + C h²`.
    pub fn abc(&self) -> (f64, f64, f64) {
        (
            self.su.cross(self.sv).dot(self.n),
            (self.su.cross(self.nv) + self.nu.cross(self.sv)).dot(self.n),
            self.nu.cross(self.nv).dot(self.n),
        )
    }

    /// A local orthonormal frame (e1 along S_u, e2, N).
    pub fn frame(&self) -> (DVec3, DVec3) {
        let e1 = (self.su - self.n * self.n.dot(self.su)).normalize();
        (e1, self.n.cross(e1))
    }
}

impl Surface {
    pub fn new(arg: &'static str, points: &[DVec3], nu: usize, nv: usize) -> Result<Surface> {
        if nu < 2 || nv < 2 || nu.checked_mul(nv) != Some(points.len()) {
            return Err(InputError::new(arg, "need a grid of at least 2 × 2 points"));
        }
        if let Some(i) = points.iter().position(|p| !p.is_finite()) {
            return Err(InputError::new(arg, format!("point {i} is not finite")));
        }
        // the call, for out-of-memory errors
        let call = if arg == "rest_surface" {
            "SurfaceBinding"
        } else {
            "SurfaceBinding.deform"
        };
        let (lo, hi) = crate::frames::geometry::bounds(points);
        let k = scale::curve_exponent(lo, hi).unwrap_or(0);
        let pts = if k == 0 {
            alloc::copied(call, points)?
        } else {
            scale::try_scaled(call, points, k)?
        };
        let points = &pts[..];
        let at = |i: usize, j: usize| points[i * nv + j];
        let scale = points
            .iter()
            .fold(0.0f64, |m, p| m.max(p.abs().max_element()));
        for i in 0..nu {
            for j in 0..nv {
                for (a, b) in [(i + 1, j), (i, j + 1)] {
                    if a < nu && b < nv && (at(a, b) - at(i, j)).length() <= 1e-12 * scale {
                        return Err(InputError::new(
                            arg,
                            format!("grid points ({i}, {j}) and ({a}, {b}) repeat the same point"),
                        ));
                    }
                }
            }
        }
        let mut n = alloc::with_capacity(call, nu * nv)?;
        for i in 0..nu {
            for j in 0..nv {
                let du = at((i + 1).min(nu - 1), j) - at(i.saturating_sub(1), j);
                let dv = at(i, (j + 1).min(nv - 1)) - at(i, j.saturating_sub(1));
                let c = du.cross(dv);
                let l = c.length();
                if !(l > 1e-300) || !(l > 1e-12 * du.length() * dv.length()) {
                    return Err(InputError::new(
                        arg,
                        format!("grid point ({i}, {j}): degenerate (repeated points)"),
                    ));
                }
                n.push(c / l);
            }
        }
        let d = derivatives(call, points, &n, nu, nv)?;
        if let Some((i, j)) = folded(points, &n, &d, nu, nv) {
            return Err(InputError::new(
                arg,
                format!("cell ({i}, {j}) folds over; sample the surface more finely"),
            ));
        }
        Ok(Surface {
            scale: Pow2::new(k),
            nu,
            nv,
            s: pts,
            n,
            d,
        })
    }

    /// The surface with the offset laid along the given directions `dirs` (one per sample,
    /// named `dir_arg`, made unit) instead of the sample normals, interpolated over the cells
    /// exactly as the normals are (bicubic Hermite of the samples with central-difference
    /// derivatives, then made unit: C¹). The volume element `det[S_u + hD_u, S_v + hD_v, D]`
    /// and so the offset correction hold for any unit direction field `D` transverse to the
    /// surface; a direction within the surface (or on its other side) is refused.
    pub fn with_directions(
        arg: &'static str,
        points: &[DVec3],
        nu: usize,
        nv: usize,
        dir_arg: &'static str,
        dirs: &[DVec3],
    ) -> Result<Surface> {
        let mut sf = Surface::new(arg, points, nu, nv)?;
        if dirs.len() != nu * nv {
            return Err(InputError::new(
                dir_arg,
                format!(
                    "expected {} directions like the grid, got {}",
                    nu * nv,
                    dirs.len()
                ),
            ));
        }
        let mut n = alloc::with_capacity("SurfaceBinding.deform", nu * nv)?;
        for (k, (&g, &normal)) in dirs.iter().zip(&sf.n).enumerate() {
            let (i, j) = (k / nv, k % nv);
            // directions of any finite size (scaled by their largest component first)
            let Some(g) = scale::normalize(g) else {
                return Err(InputError::new(
                    dir_arg,
                    format!("grid point ({i}, {j}): not a finite non-zero vector"),
                ));
            };
            let c = g.dot(normal);
            if !(c > 1e-3) {
                return Err(InputError::new(
                    dir_arg,
                    format!(
                        "grid point ({i}, {j}): the direction is {:.1}° from the surface normal: \
                         parallel to the surface or on its other side",
                        c.clamp(-1.0, 1.0).acos().to_degrees()
                    ),
                ));
            }
            n.push(g);
        }
        let d = derivatives("SurfaceBinding.deform", &sf.s, &n, nu, nv)?;
        if let Some((i, j)) = folded(&sf.s, &n, &d, nu, nv) {
            return Err(InputError::new(
                dir_arg,
                format!(
                    "cell ({i}, {j}): the interpolated direction reaches the surface's plane; \
                     give directions that turn less between samples"
                ),
            ));
        }
        sf.n = n;
        sf.d = d;
        Ok(sf)
    }

    #[inline]
    pub fn eval(&self, i: usize, j: usize, u: f64, v: f64) -> SurfLocal {
        eval_raw(&self.s, &self.n, &self.d, self.nv, i, j, u, v)
    }
}

/// Per sample: `[∂S/∂i, ∂S/∂j, ∂n/∂i, ∂n/∂j]` by central differences.
fn derivatives(
    call: &'static str,
    points: &[DVec3],
    n: &[DVec3],
    nu: usize,
    nv: usize,
) -> Result<Vec<[DVec3; 4]>> {
    let mut d = alloc::with_capacity(call, nu * nv)?;
    for i in 0..nu {
        for j in 0..nv {
            let (su, sv) = grid_diff(points, nu, nv, i, j);
            let (mu, mv) = grid_diff(n, nu, nv, i, j);
            d.push([su, sv, mu, mv]);
        }
    }
    Ok(d)
}

/// The first cell whose volume element `A = (S_u × S_v)·N` is not positive at its corners
/// or centre.
fn folded(
    points: &[DVec3],
    n: &[DVec3],
    d: &[[DVec3; 4]],
    nu: usize,
    nv: usize,
) -> Option<(usize, usize)> {
    for i in 0..nu - 1 {
        for j in 0..nv - 1 {
            for (a, b) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0), (0.5, 0.5)] {
                let l = eval_raw(points, n, d, nv, i, j, a, b);
                let (aa, _, _) = l.abc();
                if !(aa > 0.0) {
                    return Some((i, j));
                }
            }
        }
    }
    None
}

/// Bicubic Hermite patch (zero twist) of corner values `p` and per-step derivatives `du`,
/// `dv`: value and partials at `(u, v)`; C¹ across cell edges.
#[inline]
fn bicubic(p: [DVec3; 4], du: [DVec3; 4], dv: [DVec3; 4], u: f64, v: f64) -> (DVec3, DVec3, DVec3) {
    let (bu, bu1) = basis(u);
    let (bv, bv1) = basis(v);
    let (mut x, mut xu, mut xv) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
    // corners (a, b) in the order (0,0), (1,0), (0,1), (1,1)
    for (c, (a, b)) in [(0usize, 0usize), (1, 0), (0, 1), (1, 1)]
        .into_iter()
        .enumerate()
    {
        x += bu[a] * bv[b] * p[c] + bu[2 + a] * bv[b] * du[c] + bu[a] * bv[2 + b] * dv[c];
        xu += bu1[a] * bv[b] * p[c] + bu1[2 + a] * bv[b] * du[c] + bu1[a] * bv[2 + b] * dv[c];
        xv += bu[a] * bv1[b] * p[c] + bu[2 + a] * bv1[b] * du[c] + bu[a] * bv1[2 + b] * dv[c];
    }
    (x, xu, xv)
}

#[inline]
#[allow(clippy::too_many_arguments)]
fn eval_raw(
    s: &[DVec3],
    n: &[DVec3],
    d: &[[DVec3; 4]],
    nv: usize,
    i: usize,
    j: usize,
    u: f64,
    v: f64,
) -> SurfLocal {
    let k = i * nv + j;
    let ks = [k, k + nv, k + 1, k + nv + 1];
    let (sp, su, sv) = bicubic(
        ks.map(|q| s[q]),
        ks.map(|q| d[q][0]),
        ks.map(|q| d[q][1]),
        u,
        v,
    );
    let (m, mu, mv) = bicubic(
        ks.map(|q| n[q]),
        ks.map(|q| d[q][2]),
        ks.map(|q| d[q][3]),
        u,
        v,
    );
    let ml = m.length();
    let nn = m / ml;
    SurfLocal {
        s: sp,
        su,
        sv,
        n: nn,
        nu: (mu - nn * nn.dot(mu)) / ml,
        nv: (mv - nn * nn.dot(mv)) / ml,
    }
}

/// Solve `S(u,v) + h N(u,v) = p` in cell `(i, j)` by Newton from the cell centre.
fn foot(sf: &Surface, i: usize, j: usize, p: DVec3) -> Option<(f64, f64, f64)> {
    newton_foot(|u, v| sf.eval(i, j, u, v), (0.5, 0.5), p)
}

/// Solve `S(u,v) + h N(u,v) = p` by Newton's method from `(u, v) = start` (`eval`: the
/// surface at a parameter); `None` if it does not converge or leaves `|u|, |v| < 10`.
pub(super) fn newton_foot(
    eval: impl Fn(f64, f64) -> SurfLocal,
    start: (f64, f64),
    p: DVec3,
) -> Option<(f64, f64, f64)> {
    let (mut u, mut v) = start;
    let l = eval(u, v);
    let mut h = (p - l.s).dot(l.n);
    let mut polish = false;
    for _ in 0..40 {
        let l = eval(u, v);
        let r = l.s + h * l.n - p;
        let c0 = l.su + h * l.nu;
        let c1 = l.sv + h * l.nv;
        let c2 = l.n;
        let det = c0.cross(c1).dot(c2);
        if !(det.abs() > 1e-300) {
            return None;
        }
        // Cramer: J x = r
        let du = r.cross(c1).dot(c2) / det;
        let dv = c0.cross(r).dot(c2) / det;
        let dh = c0.cross(c1).dot(r) / det;
        u -= du;
        v -= dv;
        h -= dh;
        if !(u.abs() < 10.0 && v.abs() < 10.0) {
            return None;
        }
        if polish {
            return Some((u, v, h));
        }
        // quadratic convergence: one more step after a small one reaches round-off
        if du.abs() + dv.abs() < 1e-9 && dh.abs() <= 1e-9 * (1.0 + h.abs()) {
            polish = true;
        }
    }
    None
}

/// `(|h|, i, j, u, v, h)` of a foot point.
type Foot = (f64, usize, usize, f64, f64, f64);

fn try_cell(sf: &Surface, i: usize, j: usize, p: DVec3, best: &mut Option<Foot>) {
    if let Some((u, v, h)) = foot(sf, i, j, p) {
        let tol = 1e-9;
        let inside = (-tol..=1.0 + tol).contains(&u) && (-tol..=1.0 + tol).contains(&v);
        if inside && best.is_none_or(|b| h.abs() < b.0) {
            *best = Some((h.abs(), i, j, u.clamp(0.0, 1.0), v.clamp(0.0, 1.0), h));
        }
    }
}

/// Register `vertices` on the rest surface: `SURFACE_COORDS` numbers and the cell per vertex.
///
/// Polls `cancel` before each vertex (see [`crate::run::cancel`]).
pub fn bind_surface(
    rest: &Surface,
    vertices: &[DVec3],
    cancel: Cancel<'_>,
) -> Result<(Vec<i64>, Vec<f64>)> {
    super::check_vertices(vertices, rest.scale, "surface")?;
    let (to_model, to_input) = (rest.scale, rest.scale.inverse());
    let nv = vertices.len();
    let mut cell = alloc::filled("SurfaceBinding", nv, 0i64)?;
    let mut coords = alloc::filled(
        "SurfaceBinding",
        alloc::product("SurfaceBinding", SURFACE_COORDS, nv, 8)?,
        0.0,
    )?;
    let (nu_, nv_) = (rest.nu, rest.nv);
    cell.par_iter_mut()
        .zip(coords.par_chunks_mut(SURFACE_COORDS))
        .zip(vertices.par_iter())
        .for_each(|((c, out), &p)| {
            if cancel() {
                return;
            }
            let p = to_model.of3(p);
            // nearest sample, then the cells around it (then all cells if needed)
            let near = rest
                .s
                .iter()
                .enumerate()
                .fold((0, f64::INFINITY), |acc, (k, s)| {
                    let d = (p - *s).length_squared();
                    if d < acc.1 { (k, d) } else { acc }
                })
                .0;
            let (ni, nj) = (near / nv_, near % nv_);
            let mut best: Option<Foot> = None;
            for i in ni.saturating_sub(1)..ni.min(nu_ - 2) + 1 {
                for j in nj.saturating_sub(1)..nj.min(nv_ - 2) + 1 {
                    try_cell(rest, i, j, p, &mut best);
                }
            }
            if best.is_none() {
                for i in 0..nu_ - 1 {
                    for j in 0..nv_ - 1 {
                        try_cell(rest, i, j, p, &mut best);
                    }
                }
            }
            let (i, j, u, v, h, resid) = match best {
                Some((_, i, j, u, v, h)) => (i, j, u, v, h, DVec3::ZERO),
                None => {
                    // outside: attach to the nearest sample's corner, residual in the frame
                    let i = ni.min(nu_ - 2);
                    let j = nj.min(nv_ - 2);
                    let (u, v) = ((ni - i) as f64, (nj - j) as f64);
                    let l = rest.eval(i, j, u, v);
                    let (e1, e2) = l.frame();
                    let d = p - l.s;
                    (
                        i,
                        j,
                        u,
                        v,
                        0.0,
                        DVec3::new(d.dot(e1), d.dot(e2), d.dot(l.n)),
                    )
                }
            };
            let l = rest.eval(i, j, u, v);
            let (a, b, cc) = l.abc();
            let (h, resid) = (to_input.of(h), to_input.of3(resid));
            *c = (i * nv_ + j) as i64;
            out.copy_from_slice(&[u, v, h, a, b, cc, resid.x, resid.y, resid.z]);
        });
    Ok((cell, coords))
}

/// The fold-free root of `h − m h² + g h³/3 = t` (Zhuo 2014 §6.2, Eq. 43) and whether it
/// exists; without one, `h_c = 1/k_max`.
pub fn surface_offset(m: f64, g: f64, t: f64) -> (f64, bool) {
    if t == 0.0 {
        return (0.0, true);
    }
    // h → −h for t < 0: m → −m, g unchanged
    let (m, sign, t) = if t < 0.0 { (-m, -1.0, -t) } else { (m, 1.0, t) };
    let f = |h: f64| h * (1.0 + h * (-m + h * g / 3.0));
    let df = |h: f64| 1.0 + h * (-2.0 * m + h * g);
    let disc = (m * m - g).max(0.0).sqrt();
    let kmax = m + disc;
    let mut hi = if kmax > 0.0 {
        1.0 / kmax
    } else {
        f64::INFINITY
    };
    if hi.is_finite() {
        if f(hi) < t {
            return (sign * hi, false);
        }
    } else {
        hi = t.max(1e-300);
        while f(hi) < t {
            hi *= 2.0;
        }
    }
    let mut lo = 0.0;
    let mut h = t.min(hi);
    for _ in 0..200 {
        let fh = f(h) - t;
        if fh < 0.0 {
            lo = h;
        } else if fh > 0.0 {
            hi = h;
        } else {
            break;
        }
        let d = df(h);
        let next = h - fh / d;
        let next = if next > lo && next < hi {
            next
        } else {
            0.5 * (lo + hi)
        };
        if (next - h).abs() <= 1e-16 * h.abs().max(1e-300) || hi - lo <= 2.0 * f64::EPSILON * hi {
            h = next;
            break;
        }
        h = next;
    }
    (sign * h, true)
}

/// Vertices per block of a cancellable deformation ([`deform_surface`]).
const DEFORM_BLOCK: usize = 1 << 12;

/// Deform registered vertices onto the posed surface (same grid shape); `rest_exp` is the
/// exponent of the rest surface's [`Surface::scale`] (the units of `A0`, `B0`).
///
/// Polls `cancel` before every block of [`DEFORM_BLOCK`] vertices and skips the remaining blocks
/// once it says stop (`out` is then incomplete; see [`crate::run::cancel`]).
#[allow(clippy::too_many_arguments)]
pub fn deform_surface(
    posed: &Surface,
    rest_exp: i32,
    cell: &[i64],
    coords: &[f64],
    corrected: bool,
    out: &mut [DVec3],
    flags: &mut [u8],
    cancel: Cancel<'_>,
) -> Result<()> {
    check_sizes(cell.len(), coords, out, flags)?;
    let cells = (posed.nu - 1) * posed.nv;
    if let Some(i) = cell
        .iter()
        .position(|&c| c < 0 || c as usize >= cells || (c as usize) % posed.nv == posed.nv - 1)
    {
        return Err(InputError::new(
            "posed_surface",
            format!("vertex {i} is bound to a cell the posed grid does not have"),
        ));
    }
    let foot = |c: i64, x: &[f64]| {
        let (i, j) = (c as usize / posed.nv, c as usize % posed.nv);
        posed.eval(i, j, x[0], x[1])
    };
    let vertices = Bound {
        at: cell,
        coords,
        corrected,
    };
    deform_bound(posed.scale, rest_exp, vertices, out, flags, cancel, foot)
}

/// `coords` (SURFACE_COORDS per vertex), `out` and `flags` sized for `nv` vertices.
pub(super) fn check_sizes(nv: usize, coords: &[f64], out: &[DVec3], flags: &[u8]) -> Result<()> {
    if coords.len() != SURFACE_COORDS * nv || out.len() != nv || flags.len() != nv {
        return Err(InputError::new("coords", "inconsistent array sizes"));
    }
    Ok(())
}

/// Vertices registered on a surface: the cell or face `at` of each, its coordinates
/// (SURFACE_COORDS per vertex), and whether the offsets are corrected.
pub(super) struct Bound<'a> {
    pub(super) at: &'a [i64],
    pub(super) coords: &'a [f64],
    pub(super) corrected: bool,
}

/// Every vertex onto the posed surface of scale `scale` (blocks of [`DEFORM_BLOCK`] in
/// parallel, polling `cancel` before each): [`deform_vertex`] at `foot(at, x)`, the posed
/// surface's local frame at the foot of a vertex bound to cell or face `at` with coordinates
/// `x`; then [`in_range`]. Shared by [`deform_surface`] and
/// [`super::trisurf::deform_trisurface`], which check the cells or faces first.
pub(super) fn deform_bound(
    scale: Pow2,
    rest_exp: i32,
    vertices: Bound<'_>,
    out: &mut [DVec3],
    flags: &mut [u8],
    cancel: Cancel<'_>,
    foot: impl Fn(i64, &[f64]) -> SurfLocal + Sync,
) -> Result<()> {
    let Bound {
        at,
        coords,
        corrected,
    } = vertices;
    let units = Units::new(scale, rest_exp)?;
    out.par_chunks_mut(DEFORM_BLOCK)
        .zip(flags.par_chunks_mut(DEFORM_BLOCK))
        .zip(at.par_chunks(DEFORM_BLOCK))
        .zip(coords.par_chunks(SURFACE_COORDS * DEFORM_BLOCK))
        .for_each(|(((o, f), c), x)| {
            if cancel() {
                return;
            }
            let rows = o.iter_mut().zip(f.iter_mut()).zip(c);
            for (((o, f), &c), x) in rows.zip(x.chunks_exact(SURFACE_COORDS)) {
                deform_vertex(foot(c, x), corrected, &units, o, f, x);
            }
        });
    in_range(out, scale.exp(), rest_exp, cancel)
}

/// `Ok` unless a posed position `out` left the finite numbers: a binding (size exponent
/// `rest_exp`) and a pose (`q`) whose sizes differ by more than the range of f64 between
/// them, or a result past the largest float. Only looked for when a size was rescaled.
pub(super) fn in_range(out: &[DVec3], q: i32, rest_exp: i32, cancel: Cancel<'_>) -> Result<()> {
    if (q != 0 || rest_exp != 0) && !cancel() {
        if let Some(i) = out.par_iter().position_first(|p| !p.is_finite()) {
            return Err(InputError::new(
                "posed_surface",
                format!(
                    "vertex {i}: the posed position is out of range of float64 (the change \
                     of area between the rest surface and the posed surface at size {:e} is \
                     out of range)",
                    scale::ldexp(1.0, -q)
                ),
            ));
        }
    }
    Ok(())
}

/// One registered vertex (coordinates `x`) onto the posed surface `l` at its foot: its
/// position `o` and clamp flag `f`.
#[inline]
pub(super) fn deform_vertex(
    l: SurfLocal,
    corrected: bool,
    u: &Units,
    o: &mut DVec3,
    f: &mut u8,
    x: &[f64],
) {
    let resid = DVec3::new(x[6], x[7], x[8]);
    if resid != DVec3::ZERO {
        let resid = u.to_model.of3(resid);
        let (e1, e2) = l.frame();
        *o = u
            .to_input
            .of3(l.s + resid.x * e1 + resid.y * e2 + resid.z * l.n);
        *f = OUTSIDE;
        return;
    }
    let h0 = u.to_model.of(x[2]);
    if !corrected {
        *o = u.to_input.of3(l.s + h0 * l.n);
        *f = 0;
        return;
    }
    let (a1, b1, c1) = l.abc();
    let (a0, b0) = (u.area1.of(x[3]), u.len1.of(x[4]));
    let rhs = h0 * (a0 + h0 * (0.5 * b0 + h0 * x[5] / 3.0));
    let (h1, ok) = surface_offset(-0.5 * b1 / a1, c1 / a1, rhs / a1);
    *o = u.to_input.of3(l.s + h1 * l.n);
    *f = if ok { 0 } else { CLAMPED_BEND };
}

/// The powers of two between a binding's stored numbers and the posed model's units.
pub(super) struct Units {
    /// Input lengths to the posed model's units.
    to_model: Pow2,
    /// The posed model's lengths back to the input's units.
    to_input: Pow2,
    /// Rest model lengths (the stored `B0`) to the posed model's units.
    len1: Pow2,
    /// Rest model areas (the stored `A0`) to the posed model's units.
    area1: Pow2,
}

impl Units {
    /// From the posed model's scale and the exponent of the rest model's.
    pub(super) fn new(posed: Pow2, rest_exp: i32) -> Result<Units> {
        // lengths of the binding to the posed model's units, and its output back to the
        // input's
        let q = posed.exp();
        let (Some(d), Some(d2)) = (
            q.checked_sub(rest_exp),
            q.checked_sub(rest_exp).and_then(|d| d.checked_mul(2)),
        ) else {
            return Err(InputError::new("coords", "inconsistent scale exponent"));
        };
        Ok(Units {
            to_model: posed,
            to_input: posed.inverse(),
            // rest model lengths (B0) and areas (A0) in the posed model's units
            len1: Pow2::new(d),
            area1: Pow2::new(d2),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reference_values() {
        // Eq. 43 solved by hand: plane → sphere R = 2 (m = 0.5, g = 0.25),
        // cylinder R = 2 (m = 0.25)
        let (h, ok) = surface_offset(0.5, 0.25, 0.3);
        assert!(ok && (h - 0.3613575).abs() < 5e-8, "{h}");
        let (h, ok) = surface_offset(0.5, 0.25, -0.3);
        assert!(ok && (h + 0.2637024).abs() < 5e-8, "{h}");
        let (h, ok) = surface_offset(0.5, 0.25, 0.8);
        assert!(!ok && h == 2.0, "{h}");
        let (h, ok) = surface_offset(0.25, 0.0, 0.3);
        assert!(ok && (h - 0.3266799).abs() < 5e-8, "{h}");
        let (h, ok) = surface_offset(0.0, 0.0, 0.3);
        assert!(ok && (h - 0.3).abs() < 1e-15);
    }

    #[test]
    fn given_directions() {
        // a plane z = 0.5 x: the normals given back reproduce it; "up" = z lays the
        // offset vertically with A = (S_u × S_v)·z; a direction in the plane is refused
        let pts: Vec<DVec3> = (0..4)
            .flat_map(|i| (0..3).map(move |j| DVec3::new(i as f64, j as f64, 0.5 * i as f64)))
            .collect();
        let sf = Surface::new("s", &pts, 4, 3).unwrap();
        let same = Surface::with_directions("s", &pts, 4, 3, "d", &sf.n).unwrap();
        let (a, b) = (sf.eval(1, 0, 0.3, 0.6), same.eval(1, 0, 0.3, 0.6));
        assert!((a.n - b.n).length() < 1e-15 && a.abc() == b.abc());
        let up = Surface::with_directions("s", &pts, 4, 3, "d", &[DVec3::Z * 2.0; 12]).unwrap();
        let l = up.eval(2, 1, 0.5, 0.5);
        assert!((l.n - DVec3::Z).length() < 1e-15);
        let (a, b, c) = l.abc();
        assert!((a - 1.0).abs() < 1e-14 && b.abs() < 1e-14 && c.abs() < 1e-14);
        let err = Surface::with_directions("s", &pts, 4, 3, "d", &[DVec3::Y; 12]).unwrap_err();
        assert!(err.to_string().starts_with("d: grid point (0, 0)"), "{err}");
    }
}
