//! The column-wise kernels of a ring: the profile's stored columns and one ring's vertices and
//! normals, one array per quantity, computed bit for bit as glam's `DVec3` arithmetic.

use glam::DVec3;
use std::ops::Range;

use super::Profile;
use super::scale::{Real, unscaled};

/// A ring's centre and the images of the profile's axes.
pub(super) type Axes = (DVec3, DVec3, DVec3);

/// One ring of the smooth swept surface.
#[derive(Clone, Copy)]
pub(super) struct Geo {
    /// Spine sample.
    pub(super) k: usize,
    /// Centre and profile axes of the smooth surface.
    pub(super) b: Axes,
    /// The axes with the mitre stretch `M(a) = a + (f − 1)(a·k)k`: vertex `j` is
    /// `x + a_j·ma + b_j·mb`.
    pub(super) ma: DVec3,
    pub(super) mb: DVec3,
    pub(super) t: DVec3,
}

/// The stored columns of a profile (`cols`: one more than the profile for split seams),
/// one array per quantity: the profile vertex `p`, the weights `w` of the ring's six cross
/// products in the normal (see [`Rings::normal_crosses`]), from the difference `dp` of the
/// vertex's neighbours (the derivative around the profile, central; one-sided at the ends of
/// an open profile), `(dp.x, dp.y, dp.x p.x, dp.x p.y, dp.y p.x, dp.y p.y)`, and v.
///
/// [`Rings::normal_crosses`]: super::rings::Rings::normal_crosses
pub(super) struct Columns {
    px: Vec<f64>,
    py: Vec<f64>,
    /// The edge from the column's profile vertex to the next (`p[j + 1] − p[j]`, wrapping).
    ex: Vec<f64>,
    ey: Vec<f64>,
    w: [Vec<f64>; 6],
    v: Vec<f64>,
}

impl Columns {
    pub(super) fn of(p: &Profile, cols: usize) -> Columns {
        let mut c = Columns {
            px: Vec::with_capacity(cols),
            py: Vec::with_capacity(cols),
            ex: Vec::with_capacity(cols),
            ey: Vec::with_capacity(cols),
            w: Default::default(),
            v: Vec::with_capacity(cols),
        };
        c.fill(p, 0..cols);
        c
    }

    /// Stored columns `js` (replacing the ones held).
    pub(super) fn fill(&mut self, p: &Profile, js: Range<usize>) {
        let m = p.len();
        let c = self;
        c.px.clear();
        c.py.clear();
        c.ex.clear();
        c.ey.clear();
        c.w.iter_mut().for_each(Vec::clear);
        c.v.clear();
        for j in js {
            let jj = if j == m { 0 } else { j };
            let (jp, jn) = if p.closed {
                ((jj + m - 1) % m, (jj + 1) % m)
            } else {
                (jj.saturating_sub(1), (jj + 1).min(m - 1))
            };
            let (pj, dp) = (p.points[jj], p.points[jn] - p.points[jp]);
            c.px.push(pj.x);
            c.py.push(pj.y);
            let e = p.points[if jj + 1 == m { 0 } else { jj + 1 }] - pj;
            c.ex.push(e.x);
            c.ey.push(e.y);
            let w = [
                dp.x,
                dp.y,
                dp.x * pj.x,
                dp.x * pj.y,
                dp.y * pj.x,
                dp.y * pj.y,
            ];
            for (a, wk) in c.w.iter_mut().zip(w) {
                a.push(wk);
            }
            c.v.push(if j == m { 1.0 } else { p.v[j] });
        }
    }

    /// The stored columns `r` (a piece of a ring, or all of it).
    #[inline(always)]
    pub(super) fn view(&self, r: Range<usize>) -> Cols<'_> {
        let w = &self.w;
        Cols {
            px: &self.px[r.clone()],
            py: &self.py[r.clone()],
            ex: &self.ex[r.clone()],
            ey: &self.ey[r.clone()],
            w: [
                &w[0][r.clone()],
                &w[1][r.clone()],
                &w[2][r.clone()],
                &w[3][r.clone()],
                &w[4][r.clone()],
                &w[5][r.clone()],
            ],
            v: &self.v[r],
        }
    }
}

/// A range of the [`Columns`] (all of the same length).
#[derive(Clone, Copy)]
pub(super) struct Cols<'a> {
    pub(super) px: &'a [f64],
    pub(super) py: &'a [f64],
    pub(super) ex: &'a [f64],
    pub(super) ey: &'a [f64],
    pub(super) w: [&'a [f64]; 6],
    pub(super) v: &'a [f64],
}

/// One ring's vertices and normals, one array per coordinate, computed column by column
/// with the same operations in the same order as the vector forms `x + p.x ma + p.y mb`,
/// `Σ w_k c_k` and `n / |n|` (so the results are those of glam's `DVec3` arithmetic, bit
/// for bit), in loops without branches that the compiler turns into vector instructions.
pub(super) struct RingScratch {
    vx: Vec<f64>,
    vy: Vec<f64>,
    vz: Vec<f64>,
    nx: Vec<f64>,
    ny: Vec<f64>,
    nz: Vec<f64>,
    /// `1 / |n|` (usable when finite and positive).
    rcp: Vec<f64>,
}

impl RingScratch {
    /// Room for `n` columns.
    #[inline(always)]
    pub(super) fn fit(&mut self, n: usize) {
        if self.vx.len() < n {
            *self = RingScratch::new(n);
        }
    }

    pub(super) fn new(cols: usize) -> RingScratch {
        let z = || vec![0.0; cols];
        RingScratch {
            vx: z(),
            vy: z(),
            vz: z(),
            nx: z(),
            ny: z(),
            nz: z(),
            rcp: z(),
        }
    }

    #[inline(always)]
    pub(super) fn vertices(&mut self, c: &Cols, g: &Geo) {
        let n = c.px.len();
        let (px, py) = (&c.px[..n], &c.py[..n]);
        let (vx, vy, vz) = (&mut self.vx[..n], &mut self.vy[..n], &mut self.vz[..n]);
        let (x, ma, mb) = (g.b.0, g.ma, g.mb);
        for j in 0..n {
            vx[j] = (x.x + px[j] * ma.x) + py[j] * mb.x;
            vy[j] = (x.y + px[j] * ma.y) + py[j] * mb.y;
            vz[j] = (x.z + px[j] * ma.z) + py[j] * mb.z;
        }
    }

    /// The unit normals `Σ w_k c_k / |Σ w_k c_k|`.
    #[inline(always)]
    pub(super) fn normals(&mut self, c: &Cols, cr: &[DVec3; 6]) {
        let n = c.px.len();
        let w = [
            &c.w[0][..n],
            &c.w[1][..n],
            &c.w[2][..n],
            &c.w[3][..n],
            &c.w[4][..n],
            &c.w[5][..n],
        ];
        let (nx, ny, nz) = (&mut self.nx[..n], &mut self.ny[..n], &mut self.nz[..n]);
        let rcp = &mut self.rcp[..n];
        for j in 0..n {
            let (w0, w1, w2, w3, w4, w5) = (w[0][j], w[1][j], w[2][j], w[3][j], w[4][j], w[5][j]);
            let x = w0 * cr[0].x
                + w1 * cr[1].x
                + w2 * cr[2].x
                + w3 * cr[3].x
                + w4 * cr[4].x
                + w5 * cr[5].x;
            let y = w0 * cr[0].y
                + w1 * cr[1].y
                + w2 * cr[2].y
                + w3 * cr[3].y
                + w4 * cr[4].y
                + w5 * cr[5].y;
            let z = w0 * cr[0].z
                + w1 * cr[1].z
                + w2 * cr[2].z
                + w3 * cr[3].z
                + w4 * cr[4].z
                + w5 * cr[5].z;
            let r = 1.0 / (x * x + y * y + z * z).sqrt();
            (nx[j], ny[j], nz[j], rcp[j]) = (x * r, y * r, z * r, r);
        }
    }

    /// Is the normal of column `j` usable (a finite, positive `1 / |n|`)?
    #[inline(always)]
    pub(super) fn usable(&self, j: usize) -> bool {
        let r = self.rcp[j];
        r.is_finite() && r > 0.0
    }

    /// Store the normals; false if some column's normal is not usable (left to the caller).
    #[inline(always)]
    pub(super) fn put_normals<R: Real>(&self, rn: &mut [[R; 3]]) -> bool {
        let n = rn.len();
        let (nx, ny, nz, rcp) = (&self.nx[..n], &self.ny[..n], &self.nz[..n], &self.rcp[..n]);
        for j in 0..n {
            rn[j] = [R::of(nx[j]), R::of(ny[j]), R::of(nz[j])];
        }
        rcp.iter()
            .fold(true, |a, &r| a & (r.is_finite() & (r > 0.0)))
    }

    /// Store the vertices (divided by `2^k` again for input scaled by it, see [`unscaled`]).
    #[inline(always)]
    pub(super) fn put_vertices<R: Real>(&self, rv: &mut [[R; 3]], unscale: Option<i32>) {
        let n = rv.len();
        let (vx, vy, vz) = (&self.vx[..n], &self.vy[..n], &self.vz[..n]);
        match unscale {
            None => {
                for j in 0..n {
                    rv[j] = [R::of(vx[j]), R::of(vy[j]), R::of(vz[j])];
                }
            }
            Some(k) => {
                for j in 0..n {
                    let k = Some(k);
                    rv[j] = [unscaled(vx[j], k), unscaled(vy[j], k), unscaled(vz[j], k)];
                }
            }
        }
    }
}
