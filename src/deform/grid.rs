//! Free-form tool from a sampled signed distance: Zheng's "extended spherical" field
//! (thesis §11.2.1, §11.2.5, with the exact distance-field extension of the sphere's
//! region translation) with the tool's distance interpolated by a C² tricubic B-spline.
//!
//! **Distance.** The grid holds the coefficients `c_{ijk}` (one ghost layer on each side) of
//! the uniform cubic B-spline `d(X) = Σ c_{ijk} β(ξ − i) β(η − j) β(ζ − k)`,
//! `(ξ, η, ζ) = (X − o)/h`, `β` the centred cubic B-spline; the Python constructor computes
//! them so that `d` interpolates the sampled distances at the nodes (natural end conditions).
//! `d` is C², and `∇d` is evaluated as the exact gradient of this interpolant (the basis
//! derivatives), never by differences. The basis is non-negative with unit sum, so in a cell
//! `d ≥` the smallest of its 64 coefficients: cells whose minimum is `≥ R_f` give `v = 0`
//! without evaluation, and the constructor refuses grids whose boundary cells could have
//! `d < R_f` (the support must not reach the edge of the grid).
//!
//! **Field.** With `Y = X − C` (the tool's centre), `N × B = u/|u|` and `D = b(d/R_f)` the
//! region function of [`super::cross`],
//! `p = (1 − D(d)) N·Y`, `q = (1 − D(d)) B·Y` and
//!
//! ```text
//! v = ∇p × ∇q = (1 − D)² u + (1 − D) D′ [ (∇d·u) Y − (∇d·Y) u ]
//! ```
//!
//! for any C¹ `d` with its exact gradient (not normalised: `|∇d| ≠ 1` between nodes). So `v`
//! is exactly divergence-free for the *interpolated* distance; the interpolation error only
//! changes which divergence-free field is used. Inside the tool (`d ≤ 0`) `v = u`, the tool's
//! rigid motion; beyond `d ≥ R_f` `v = 0`. A tool with `moving` set carries its grid along:
//! `d(X − u t)`, `C + u t`.

use glam::DVec3;

use super::shape::{Distance, speed_factor, translate};
use crate::error::{InputError, Result};
use crate::run::alloc;
use crate::run::cancel::Cancel;

/// A tool given by a signed-distance grid (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct GridTool {
    pub origin: DVec3,
    pub spacing: f64,
    /// Nodes per axis (the coefficient array has `n + 2` per axis).
    pub n: [usize; 3],
    coef: Vec<f64>,
    /// Per cell (`n − 1` per axis): the smallest coefficient of its 4×4×4 stencil.
    cell_min: Vec<f64>,
    pub velocity: DVec3,
    pub center: DVec3,
    pub reach: f64,
    pub linear: bool,
    pub moving: bool,
    /// `1 / spacing`, the largest node index `n − 1` (as a float) and the largest cell index
    /// `n − 2` per axis.
    inv_spacing: f64,
    top: [f64; 3],
    last: [i64; 3],
    /// `y_max[b]`: largest `|X − C|` over the cells whose smallest coefficient is below
    /// `(b + 1) R_f / BUCKETS` (a point at distance `d` lies in a cell with minimum `≤ d`).
    y_max: [f64; BUCKETS],
    /// [`GridTool::slope_bound`], computed once (a pass over every coefficient).
    slope: f64,
}

const BUCKETS: usize = 64;

/// `w·x` lane by lane (the row arithmetic of [`GridTool::spline_body`]).
#[inline(always)]
fn scale(w: f64, x: [f64; 4]) -> [f64; 4] {
    [w * x[0], w * x[1], w * x[2], w * x[3]]
}

/// `acc + w·x` lane by lane.
#[inline(always)]
fn madd(acc: [f64; 4], w: f64, x: [f64; 4]) -> [f64; 4] {
    [
        acc[0] + w * x[0],
        acc[1] + w * x[1],
        acc[2] + w * x[2],
        acc[3] + w * x[3],
    ]
}

/// Cubic B-spline weights and their derivatives at fraction `f ∈ [0, 1]`.
#[inline(always)]
fn weights(f: f64) -> ([f64; 4], [f64; 4]) {
    const SIXTH: f64 = 1.0 / 6.0;
    let g = 1.0 - f;
    let f2 = f * f;
    let f3 = f2 * f;
    (
        [
            g * g * g * SIXTH,
            (3.0 * f3 - 6.0 * f2 + 4.0) * SIXTH,
            (-3.0 * f3 + 3.0 * f2 + 3.0 * f + 1.0) * SIXTH,
            f3 * SIXTH,
        ],
        [
            -0.5 * g * g,
            0.5 * (3.0 * f2 - 4.0 * f),
            0.5 * (-3.0 * f2 + 2.0 * f + 1.0),
            0.5 * f2,
        ],
    )
}

/// [`weights`] of the four lanes of `f` at once (the same operations lane by lane).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn weights_avx2(
    f: std::arch::x86_64::__m256d,
) -> (
    [std::arch::x86_64::__m256d; 4],
    [std::arch::x86_64::__m256d; 4],
) {
    use std::arch::x86_64::{_mm256_add_pd, _mm256_mul_pd, _mm256_set1_pd, _mm256_sub_pd};
    let k = _mm256_set1_pd;
    let (add, sub, mul) = (_mm256_add_pd, _mm256_sub_pd, _mm256_mul_pd);
    const SIXTH: f64 = 1.0 / 6.0;
    let g = sub(k(1.0), f);
    let f2 = mul(f, f);
    let f3 = mul(f2, f);
    (
        [
            mul(mul(mul(g, g), g), k(SIXTH)),
            mul(add(sub(mul(k(3.0), f3), mul(k(6.0), f2)), k(4.0)), k(SIXTH)),
            mul(
                add(
                    add(add(mul(k(-3.0), f3), mul(k(3.0), f2)), mul(k(3.0), f)),
                    k(1.0),
                ),
                k(SIXTH),
            ),
            mul(f3, k(SIXTH)),
        ],
        [
            mul(mul(k(-0.5), g), g),
            mul(k(0.5), sub(mul(k(3.0), f2), mul(k(4.0), f))),
            mul(k(0.5), add(add(mul(k(-3.0), f2), mul(k(2.0), f)), k(1.0))),
            mul(k(0.5), f2),
        ],
    )
}

impl GridTool {
    /// The tool of the distance grid of `n` nodes per axis from `origin` at `spacing`, with
    /// the coefficients `coef` and, in `tool`, its velocity, centre, reach and the `linear`
    /// and `moving` flags; polls `cancel` between the planes of its passes over the cells
    /// and fails with [`InputError::stopped`] once it says stop.
    pub fn new(
        origin: DVec3,
        spacing: f64,
        n: [usize; 3],
        coef: Vec<f64>,
        tool: (DVec3, DVec3, f64, bool, bool),
        cancel: Cancel<'_>,
    ) -> Result<GridTool> {
        let (velocity, center, reach, linear, moving) = tool;
        let stop = || {
            if cancel() {
                Err(InputError::stopped())
            } else {
                Ok(())
            }
        };
        let bad = |m: String| InputError::new("field", m);
        if n.iter().any(|&k| k < 4) {
            return Err(bad(format!(
                "sdf grid needs at least 4 nodes per axis, got {n:?}"
            )));
        }
        // user numbers: sums and product checked (a wrapped one could match `coef`)
        let p = n.map(|k| k.saturating_add(2));
        let nodes = p[0].checked_mul(p[1]).and_then(|a| a.checked_mul(p[2]));
        if nodes != Some(coef.len()) {
            return Err(bad(format!(
                "sdf grid of {n:?} nodes needs {} coefficients, got {}",
                nodes.map_or_else(|| "more than usize".to_string(), |c| c.to_string()),
                coef.len()
            )));
        }
        // separable 4-wide minimum: cells are n − 1 per axis
        let c = [n[0] - 1, n[1] - 1, n[2] - 1];
        let win =
            |v: &[f64], i: usize, s: usize| v[i].min(v[i + s]).min(v[i + 2 * s]).min(v[i + 3 * s]);
        // each smaller than `coef` (checked above), allocated fallibly
        let mut mz = alloc::filled("sdf grid", p[0] * p[1] * c[2], 0.0)?;
        for i in 0..p[0] * p[1] {
            if i % p[1] == 0 {
                stop()?;
            }
            for k in 0..c[2] {
                mz[i * c[2] + k] = win(&coef, i * p[2] + k, 1);
            }
        }
        let mut my = alloc::filled("sdf grid", p[0] * c[1] * c[2], 0.0)?;
        for i in 0..p[0] {
            stop()?;
            for j in 0..c[1] {
                for k in 0..c[2] {
                    my[(i * c[1] + j) * c[2] + k] = win(&mz, (i * p[1] + j) * c[2] + k, c[2]);
                }
            }
        }
        let mut cell_min = alloc::filled("sdf grid", c[0] * c[1] * c[2], 0.0)?;
        for i in 0..c[0] {
            stop()?;
            for j in 0..c[1] {
                for k in 0..c[2] {
                    cell_min[(i * c[1] + j) * c[2] + k] =
                        win(&my, (i * c[1] + j) * c[2] + k, c[1] * c[2]);
                }
            }
        }
        let mut y_max = [0.0f64; BUCKETS];
        let half = 0.5 * spacing * 3f64.sqrt();
        for i in 0..c[0] {
            stop()?;
            for j in 0..c[1] {
                for k in 0..c[2] {
                    let m = cell_min[(i * c[1] + j) * c[2] + k];
                    if m >= reach {
                        continue;
                    }
                    let edge = i == 0
                        || j == 0
                        || k == 0
                        || i == c[0] - 1
                        || j == c[1] - 1
                        || k == c[2] - 1;
                    if edge {
                        return Err(InputError::new(
                            "grid",
                            format!(
                                "the field's support (distance < reach {reach}) reaches the edge \
                                 of the grid at cell ({i}, {j}, {k}); pad the grid so that the \
                                 distance is ≥ reach on its outer cells"
                            ),
                        ));
                    }
                    let mid = origin
                        + DVec3::new(i as f64 + 0.5, j as f64 + 0.5, k as f64 + 0.5) * spacing;
                    let b = ((m / reach * BUCKETS as f64).max(0.0) as usize).min(BUCKETS - 1);
                    y_max[b] = y_max[b].max((mid - center).length() + half);
                }
            }
        }
        for b in 1..BUCKETS {
            y_max[b] = y_max[b].max(y_max[b - 1]);
        }
        let slope = slope_bound(&coef, n, spacing);
        Ok(GridTool {
            origin,
            spacing,
            n,
            coef,
            cell_min,
            slope,
            inv_spacing: 1.0 / spacing,
            top: n.map(|k| (k - 1) as f64),
            last: n.map(|k| k as i64 - 2),
            velocity,
            center,
            reach,
            linear,
            moving,
            y_max,
        })
    }

    /// The interpolated distance and its exact gradient at `x` (tool frame), or `None` where
    /// `d ≥ R_f` is certain (outside the grid, or a cell whose coefficients are all `≥ R_f`).
    /// Inlined into the callers' lane loops: the cull, taken by most points, costs no call.
    #[inline(always)]
    pub fn distance(&self, x: DVec3) -> Option<(f64, DVec3)> {
        let g = (x - self.origin) * self.inv_spacing;
        let n = self.n;
        // inside the grid, 0 ≤ g ≤ n − 1 on every axis (a NaN fails): one test, before any
        // conversion, for the many points away from the tool
        let inside = (g.x >= 0.0)
            & (g.y >= 0.0)
            & (g.z >= 0.0)
            & (g.x <= self.top[0])
            & (g.y <= self.top[1])
            & (g.z <= self.top[2]);
        if !inside {
            return None;
        }
        let mut idx = [0usize; 3];
        let mut fr = [0.0; 3];
        for a in 0..3 {
            // 0 ≤ g ≤ n − 1, so truncation is the floor (no libm call on the baseline
            // target); through i64, whose conversions are single instructions
            let i = (g[a] as i64).min(self.last[a]);
            idx[a] = i as usize;
            fr[a] = g[a] - i as f64;
        }
        let c = [n[0] - 1, n[1] - 1, n[2] - 1];
        if self.cell_min[(idx[0] * c[1] + idx[1]) * c[2] + idx[2]] >= self.reach {
            return None;
        }
        self.spline(idx, fr)
    }

    /// The B-spline and its gradient in cell `idx` at fractions `fr` (kept out of line, so
    /// that the cull of [`Self::distance`], taken by most points, stays short).
    ///
    /// On x86-64 processors with AVX2 the contraction runs on 256-bit vectors, a row of 4
    /// coefficients per register ([`Self::spline_avx2`], chosen at run time as the frames'
    /// scan chooses its AVX2 build, `crate::frames::fused`). Its operations are, lane by lane,
    /// the IEEE operations of [`Self::spline_body`] in the same order (Rust never fuses a
    /// multiply and an add on its own), so both give the same bits (a unit test compares
    /// them).
    #[inline(never)]
    fn spline(&self, idx: [usize; 3], fr: [f64; 3]) -> Option<(f64, DVec3)> {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: `spline_avx2` only needs the processor to support AVX2, checked just
            // above.
            return unsafe { self.spline_avx2(idx, fr) };
        }
        self.spline_body(idx, fr)
    }

    /// Layer `a` of the stencil of cell `idx`: its row `b` (4 coefficients along z) starts
    /// at `b · (n_z + 2)`.
    #[inline(always)]
    fn layer(&self, idx: [usize; 3], a: usize) -> Option<&[f64]> {
        let (py, pz) = (self.n[1] + 2, self.n[2] + 2);
        let first = ((idx[0] + a) * py + idx[1]) * pz + idx[2];
        self.coef.get(first..first + 3 * pz + 4)
    }

    /// [`Self::spline_body`] on 256-bit vectors (the same operations lane by lane).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn spline_avx2(&self, idx: [usize; 3], fr: [f64; 3]) -> Option<(f64, DVec3)> {
        use std::arch::x86_64::{
            __m256d, _mm256_add_pd, _mm256_broadcastsd_pd, _mm256_castpd256_pd128, _mm256_hadd_pd,
            _mm256_mul_pd, _mm256_permute2f128_pd, _mm256_permute4x64_pd, _mm256_set1_pd,
            _mm256_setr_pd, _mm256_unpacklo_pd,
        };
        // the weights of the three axes at once (lanes x, y, z), then lane x of the k-th
        // weight for layer k, lane y for row k, and the z weights gathered into one vector
        let (w, dw) = weights_avx2(_mm256_setr_pd(fr[0], fr[1], fr[2], 0.0));
        let wx = w.map(|v| _mm256_broadcastsd_pd(_mm256_castpd256_pd128(v)));
        let dx = dw.map(|v| _mm256_broadcastsd_pd(_mm256_castpd256_pd128(v)));
        let wy = w.map(|v| _mm256_permute4x64_pd::<0x55>(v));
        let dy = dw.map(|v| _mm256_permute4x64_pd::<0x55>(v));
        let lanes_z = |v: [__m256d; 4]| {
            _mm256_permute2f128_pd::<0x31>(
                _mm256_unpacklo_pd(v[0], v[1]),
                _mm256_unpacklo_pd(v[2], v[3]),
            )
        };
        let (vz, vdz) = (lanes_z(w), lanes_z(dw));
        let pz = self.n[2] + 2;
        let mut e = [_mm256_set1_pd(0.0); 3];
        for a in 0..4 {
            let layer = self.layer(idx, a)?;
            let mut s = [_mm256_set1_pd(0.0); 2];
            for b in 0..4 {
                let r = &layer[b * pz..b * pz + 4];
                let r = _mm256_setr_pd(r[0], r[1], r[2], r[3]);
                let (ty, tdy) = (_mm256_mul_pd(wy[b], r), _mm256_mul_pd(dy[b], r));
                s = if b == 0 {
                    [ty, tdy]
                } else {
                    [_mm256_add_pd(s[0], ty), _mm256_add_pd(s[1], tdy)]
                };
            }
            let t = [
                _mm256_mul_pd(wx[a], s[0]),
                _mm256_mul_pd(dx[a], s[0]),
                _mm256_mul_pd(wx[a], s[1]),
            ];
            e = if a == 0 {
                t
            } else {
                [
                    _mm256_add_pd(e[0], t[0]),
                    _mm256_add_pd(e[1], t[1]),
                    _mm256_add_pd(e[2], t[2]),
                ]
            };
        }
        // the four dot products `(u₀w₀ + u₁w₁) + (u₂w₂ + u₃w₃)`: pairs by `hadd`, then the
        // pair sums of each product brought into one lane
        let p: [__m256d; 4] = [
            _mm256_mul_pd(e[0], vz),
            _mm256_mul_pd(e[1], vz),
            _mm256_mul_pd(e[2], vz),
            _mm256_mul_pd(e[0], vdz),
        ];
        let (h01, h23) = (_mm256_hadd_pd(p[0], p[1]), _mm256_hadd_pd(p[2], p[3]));
        let sum = _mm256_add_pd(
            _mm256_permute2f128_pd::<0x20>(h01, h23),
            _mm256_permute2f128_pd::<0x31>(h01, h23),
        );
        let [d, gx, gy, gz]: [f64; 4] = bytemuck::cast(sum);
        Some((d, DVec3::new(gx, gy, gz) * self.inv_spacing))
    }

    /// The work of [`Self::spline`].
    #[inline(always)]
    fn spline_body(&self, idx: [usize; 3], fr: [f64; 3]) -> Option<(f64, DVec3)> {
        let n = self.n;
        let (wx, dx) = weights(fr[0]);
        let (wy, dy) = weights(fr[1]);
        let (wz, dz) = weights(fr[2]);
        // separable contraction, the z direction kept as a 4-vector to the end: for each x
        // layer `a`, `s0 = Σ_b wy_b c_ab·` and `sy = Σ_b dy_b c_ab·` (rows of 4 along z), then
        // `e0 = Σ_a wx_a s0`, `ex = Σ_a dx_a s0`, `ey = Σ_a wx_a sy`; finally the z weights:
        // `d = e0·wz`, `∂ξ d = ex·wz`, `∂η d = ey·wz`, `∂ζ d = e0·dz`
        let pz = n[2] + 2;
        let mut e = [[0.0; 4]; 3];
        for a in 0..4 {
            let layer = self.layer(idx, a)?;
            let row = |b: usize| -> [f64; 4] {
                let r = &layer[b * pz..b * pz + 4];
                [r[0], r[1], r[2], r[3]]
            };
            let r0 = row(0);
            let (mut s0, mut sy) = (scale(wy[0], r0), scale(dy[0], r0));
            for b in 1..4 {
                let r = row(b);
                s0 = madd(s0, wy[b], r);
                sy = madd(sy, dy[b], r);
            }
            e = if a == 0 {
                [scale(wx[0], s0), scale(dx[0], s0), scale(wx[0], sy)]
            } else {
                [
                    madd(e[0], wx[a], s0),
                    madd(e[1], dx[a], s0),
                    madd(e[2], wx[a], sy),
                ]
            };
        }
        let [e0, ex, ey] = e;
        let dot =
            |u: &[f64; 4], w: &[f64; 4]| (u[0] * w[0] + u[1] * w[1]) + (u[2] * w[2] + u[3] * w[3]);
        let (d, gx, gy, gz) = (dot(&e0, &wz), dot(&ex, &wz), dot(&ey, &wz), dot(&e0, &dz));
        Some((d, DVec3::new(gx, gy, gz) * self.inv_spacing))
    }

    #[inline]
    pub fn eval(&self, x: DVec3, t: f64) -> DVec3 {
        let x = if self.moving {
            x - self.velocity * t
        } else {
            x
        };
        match self.distance(x) {
            Some((d, n)) => translate(
                d,
                n,
                x - self.center,
                self.velocity,
                self.reach,
                self.linear,
            ),
            None => DVec3::ZERO,
        }
    }

    /// `|u| max_d [(1 − D)² + (1 − D) D′ L(d)]`, `L(d)` the largest `|Y|` of the cells that
    /// can reach distance `d` (with `|∇d| ≈ 1`, a distance's gradient).
    pub fn max_speed(&self) -> f64 {
        let y = &self.y_max;
        let rf = self.reach;
        self.velocity.length()
            * speed_factor(rf, self.linear, |d| {
                y[((d / rf * BUCKETS as f64) as usize).min(BUCKETS - 1)]
            })
    }
}

/// `x[c] = f(x[c], y[c])` over one row, in parallel pieces when `wide`.
#[inline]
fn zip_rows(x: &mut [f64], y: &[f64], wide: bool, f: impl Fn(f64, f64) -> f64 + Sync) {
    use rayon::prelude::*;
    let piece = |(x, y): (&mut [f64], &[f64])| {
        for (x, &y) in x.iter_mut().zip(y) {
            *x = f(*x, y);
        }
    };
    if wide {
        x.par_chunks_mut(1 << 12)
            .zip(y.par_chunks(1 << 12))
            .for_each(piece);
    } else {
        piece((x, y));
    }
}

/// The coefficients, `(nx + 2) (ny + 2) (nz + 2)` in C order, of the natural cubic B-spline
/// interpolating `values` sampled on a unit grid of `n = (nx, ny, nz)` nodes (C order),
/// written into `out`. Per axis, on every line `d_0 … d_{m−1}` along it: `c_0 = d_0`,
/// `c_{m−1} = d_{m−1}`, `c_{i−1} + 4c_i + c_{i+1} = 6d_i` inside (solved by the Thomas
/// algorithm), and one ghost coefficient each side, `c_{−1} = 2c_0 − c_1` (zero second
/// derivative at the end nodes). The axes are filtered in turn, each line's operations in
/// the order of the NumPy formulation (the same bits). At least 4 nodes per axis (errors name
/// `grid`); polls `cancel` between lines and between the steps of long ones (`out`
/// incomplete once it says stop; see [`crate::run::cancel`]).
pub fn spline_coefficients(
    values: &[f64],
    n: [usize; 3],
    out: &mut [f64],
    cancel: Cancel<'_>,
) -> Result<()> {
    if n.iter().any(|&k| k < 4) {
        return Err(InputError::new(
            "grid",
            format!("expected at least 4 nodes per axis, got shape {n:?}"),
        ));
    }
    let p = n.map(|k| k + 2);
    let size = |s: [usize; 3]| s[0].checked_mul(s[1]).and_then(|a| a.checked_mul(s[2]));
    if size(n) != Some(values.len()) || size(p) != Some(out.len()) {
        return Err(InputError::new(
            "grid",
            "values and coefficients do not match the shape",
        ));
    }
    const CALL: &str = "grid coefficients";
    // axis 0: (nx, ny, nz) -> (nx+2, ny, nz); axis 1: -> (nx+2, ny+2, nz); axis 2: -> out
    let mut a = alloc::filled(CALL, p[0] * n[1] * n[2], 0.0)?;
    if !prefilter_axis(values, n[0], n[1] * n[2], &mut a, cancel)? {
        return Ok(());
    }
    let mut b = alloc::filled(CALL, p[0] * p[1] * n[2], 0.0)?;
    if !prefilter_axis(&a, n[1], n[2], &mut b, cancel)? {
        return Ok(());
    }
    drop(a);
    prefilter_axis(&b, n[2], 1, out, cancel)?;
    Ok(())
}

/// One axis of [`spline_coefficients`]: `src` of shape `(outer, m, inner)` into `dst` of
/// shape `(outer, m + 2, inner)`, each step of the recurrence over a whole row of `inner`
/// values (as NumPy's planes); in parallel over the slabs, and within the rows when they are
/// long. Returns `false` when stopped.
fn prefilter_axis(
    src: &[f64],
    m: usize,
    inner: usize,
    dst: &mut [f64],
    cancel: Cancel<'_>,
) -> Result<bool> {
    use rayon::prelude::*;
    use std::sync::atomic::{AtomicBool, Ordering};
    // the forward elimination's factors depend on m only
    let k = m - 2;
    let mut cp = alloc::filled("grid coefficients", k, 0.0)?;
    cp[0] = 0.25;
    for i in 1..k {
        cp[i] = 1.0 / (4.0 - cp[i - 1]);
    }
    let stopped = AtomicBool::new(false);
    // a poll before every slab, and before every step of slabs of long rows
    let step_polls = inner >= 1 << 12;
    let stop = || {
        let s = stopped.load(Ordering::Relaxed) || cancel();
        if s {
            stopped.store(true, Ordering::Relaxed);
        }
        s
    };
    // the first axis has a single slab: its parallelism is within the rows
    let wide = inner >= 1 << 14;
    let rows = |x: &mut [f64], y: &[f64], f: fn(f64, f64, f64) -> f64, w: f64| {
        zip_rows(x, y, wide, |x, y| f(x, y, w));
    };
    let slabs = dst
        .par_chunks_mut((m + 2) * inner)
        .zip(src.par_chunks(m * inner));
    slabs
        .with_min_len(1.max((1 << 14) / (m * inner).max(1)))
        .for_each(|(o, a)| {
            if stop() {
                return;
            }
            let row = |i: usize| i * inner..(i + 1) * inner;
            // rows 2..m of `o` hold the right-hand side, then the solution (NumPy's `rhs`)
            o[row(1)].copy_from_slice(&a[row(0)]);
            o[row(m)].copy_from_slice(&a[row(m - 1)]);
            for j in 0..k {
                rows(&mut o[row(j + 2)], &a[row(j + 1)], |_, v, _| 6.0 * v, 0.0);
            }
            rows(&mut o[row(2)], &a[row(0)], |x, v, _| x - v, 0.0);
            rows(&mut o[row(k + 1)], &a[row(m - 1)], |x, v, _| x - v, 0.0);
            for x in &mut o[row(2)] {
                *x *= 0.25;
            }
            for i in 1..k {
                if step_polls && stop() {
                    return;
                }
                let w = 4.0 - cp[i - 1];
                let (head, tail) = o.split_at_mut((i + 2) * inner);
                rows(
                    &mut tail[..inner],
                    &head[(i + 1) * inner..],
                    |x, p, w| (x - p) / w,
                    w,
                );
            }
            for i in (0..k.saturating_sub(1)).rev() {
                if step_polls && stop() {
                    return;
                }
                let (head, tail) = o.split_at_mut((i + 3) * inner);
                let next = &tail[..inner];
                rows(
                    &mut head[(i + 2) * inner..],
                    next,
                    |x, n, c| x - c * n,
                    cp[i],
                );
            }
            // the ghosts 2c₁ − c₂ (first row from rows 1, 2; last from rows m, m − 1)
            let (first, rest) = o.split_at_mut(inner);
            first.copy_from_slice(&rest[..inner]);
            rows(
                first,
                &rest[inner..2 * inner],
                |c1, c2, _| 2.0 * c1 - c2,
                0.0,
            );
            let (rest, last) = o.split_at_mut((m + 1) * inner);
            last.copy_from_slice(&rest[m * inner..]);
            rows(
                last,
                &rest[(m - 1) * inner..m * inner],
                |c1, c2, _| 2.0 * c1 - c2,
                0.0,
            );
        });
    Ok(!stopped.into_inner())
}

/// Cells per reach below which a grid is too coarse for the blend region.
pub const MIN_CELLS_PER_REACH: f64 = 4.0;

/// The tool of `spinal.fields.sdf_tool` from its B-spline coefficients, an array of shape
/// `shape = (nx + 2, ny + 2, nz + 2)` for a distance sampled on `(nx, ny, nz)` nodes,
/// validated: at least 4 nodes per axis, finite vectors, positive spacing and reach, at
/// least [`MIN_CELLS_PER_REACH`] cells per reach, and a support that stays inside the grid
/// ([`GridTool::new`]). The coefficients are copied (fallibly); `cancel` is polled in the
/// checks and the passes over the cells ([`GridTool::new`]).
#[allow(clippy::too_many_arguments)]
pub fn grid_tool(
    origin: DVec3,
    spacing: f64,
    shape: [usize; 3],
    coef: &[f64],
    velocity: DVec3,
    center: DVec3,
    reach: f64,
    linear: bool,
    moving: bool,
    cancel: Cancel<'_>,
) -> Result<GridTool> {
    if shape.iter().any(|&k| k < 6) || coef.len() != shape.iter().product::<usize>() {
        return Err(InputError::new(
            "grid",
            format!("expected at least 4 nodes per axis, got shape {shape:?}"),
        ));
    }
    let n = shape.map(|k| k - 2);
    let origin = super::finite3("origin", origin)?;
    let velocity = super::finite3("velocity", velocity)?;
    let center = super::finite3("center", center)?;
    let spacing = super::positive("spacing", spacing)?;
    let reach = super::positive("reach", reach)?;
    if !(reach >= MIN_CELLS_PER_REACH * spacing) {
        return Err(InputError::new(
            "spacing",
            format!(
                "grid too coarse: spacing {spacing:.4} must be at most reach/{MIN_CELLS_PER_REACH} \
                 = {:.4} (the blend region needs {MIN_CELLS_PER_REACH} cells)",
                reach / MIN_CELLS_PER_REACH
            ),
        ));
    }
    if let Some(i) = crate::frames::validate::first_bad(coef, |c| c.is_finite(), cancel) {
        return Err(InputError::new(
            "grid",
            format!("spline coefficient {i} is not finite"),
        ));
    }
    let coef = alloc::copied("grid", coef)?;
    let t = (velocity, center, reach, linear, moving);
    let tool = GridTool::new(origin, spacing, n, coef, t, cancel)?;
    super::bounded("velocity", tool)
}

impl super::Tool for GridTool {
    fn wants_locality(&self) -> bool {
        true
    }
    #[inline]
    fn velocity(&self, x: DVec3, t: f64, _tm: f64) -> DVec3 {
        self.eval(x, t)
    }
    fn max_speed(&self) -> f64 {
        GridTool::max_speed(self)
    }
    fn length_scale(&self) -> f64 {
        self.reach
    }
    /// The grid's own motion: `|velocity|` when it moves with the tool, else 0.
    fn support_speed(&self) -> f64 {
        if self.moving {
            self.velocity.length()
        } else {
            0.0
        }
    }
    fn shape(&self) -> Option<super::shape::ToolShape> {
        Some(super::shape::ToolShape {
            shape: super::shape::Shape::Grid(std::sync::Arc::new(self.clone())),
            power: None,
        })
    }
}

impl GridTool {
    /// An upper bound of `|X − C|` over the cells whose smallest coefficient is below the
    /// reach (every point with `d < R`, inside the tool included).
    pub fn support_extent(&self) -> f64 {
        self.y_max[BUCKETS - 1]
    }

    /// An upper bound of `|∇d|`: each partial derivative of the B-spline is a spline of one
    /// degree less whose coefficients are the differences `Δc/h` along that axis (a convex
    /// combination of them), so `|∂d/∂x_a| ≤ max |Δ_a c|/h` (computed when the tool is built).
    pub fn slope_bound(&self) -> f64 {
        self.slope
    }
}

/// [`GridTool::slope_bound`] of the coefficients `coef` (`n + 2` per axis) at `spacing`.
fn slope_bound(coef: &[f64], n: [usize; 3], spacing: f64) -> f64 {
    let p = [n[0] + 2, n[1] + 2, n[2] + 2];
    let stride = [p[1] * p[2], p[2], 1];
    let mut m = [0.0f64; 3];
    for i in 0..p[0] {
        for j in 0..p[1] {
            for k in 0..p[2] {
                let at = i * stride[0] + j * stride[1] + k;
                for (a, idx) in [i, j, k].into_iter().enumerate() {
                    if idx + 1 < p[a] {
                        m[a] = m[a].max((coef[at + stride[a]] - coef[at]).abs());
                    }
                }
            }
        }
    }
    DVec3::from(m).length() / spacing
}

impl Distance for GridTool {
    #[inline(always)]
    fn distance(&self, x: DVec3) -> Option<(f64, DVec3)> {
        GridTool::distance(self, x)
    }
    fn reach(&self) -> f64 {
        self.reach
    }
    fn center(&self) -> DVec3 {
        self.center
    }
    fn extent(&self) -> f64 {
        self.support_extent()
    }
    fn gradient_bound(&self) -> f64 {
        self.slope_bound()
    }
    fn wants_locality(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod timing;
