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

use super::cross::{speed_factor, translate};
use crate::alloc;
use crate::error::{InputError, Result};

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
}

const BUCKETS: usize = 64;

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

impl GridTool {
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        origin: DVec3,
        spacing: f64,
        n: [usize; 3],
        coef: Vec<f64>,
        velocity: DVec3,
        center: DVec3,
        reach: f64,
        linear: bool,
        moving: bool,
    ) -> Result<GridTool> {
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
            for k in 0..c[2] {
                mz[i * c[2] + k] = win(&coef, i * p[2] + k, 1);
            }
        }
        let mut my = alloc::filled("sdf grid", p[0] * c[1] * c[2], 0.0)?;
        for i in 0..p[0] {
            for j in 0..c[1] {
                for k in 0..c[2] {
                    my[(i * c[1] + j) * c[2] + k] = win(&mz, (i * p[1] + j) * c[2] + k, c[2]);
                }
            }
        }
        let mut cell_min = alloc::filled("sdf grid", c[0] * c[1] * c[2], 0.0)?;
        for i in 0..c[0] {
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
        Ok(GridTool {
            origin,
            spacing,
            n,
            coef,
            cell_min,
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
    #[inline]
    pub fn distance(&self, x: DVec3) -> Option<(f64, DVec3)> {
        let g = (x - self.origin) * self.inv_spacing;
        let n = self.n;
        let mut idx = [0usize; 3];
        let mut fr = [0.0; 3];
        for a in 0..3 {
            if !(g[a] >= 0.0 && g[a] <= self.top[a]) {
                return None;
            }
            // 0 ≤ g ≤ n − 1 here, so truncation is the floor (no libm call on the baseline
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
    #[inline(never)]
    fn spline(&self, idx: [usize; 3], fr: [f64; 3]) -> Option<(f64, DVec3)> {
        let n = self.n;
        let (wx, dx) = weights(fr[0]);
        let (wy, dy) = weights(fr[1]);
        let (wz, dz) = weights(fr[2]);
        // separable contraction, the z direction kept as a 4-vector to the end: for each x
        // layer `a`, `s0 = Σ_b wy_b c_ab·` and `sy = Σ_b dy_b c_ab·` (rows of 4 along z), then
        // `e0 = Σ_a wx_a s0`, `ex = Σ_a dx_a s0`, `ey = Σ_a wx_a sy`; finally the z weights:
        // `d = e0·wz`, `∂ξ d = ex·wz`, `∂η d = ey·wz`, `∂ζ d = e0·dz`
        let (py, pz) = (n[1] + 2, n[2] + 2);
        let (mut e0, mut ex, mut ey) = ([0.0; 4], [0.0; 4], [0.0; 4]);
        for a in 0..4 {
            let (mut s0, mut sy) = ([0.0; 4], [0.0; 4]);
            for b in 0..4 {
                let base = ((idx[0] + a) * py + idx[1] + b) * pz + idx[2];
                let cs = self.coef.get(base..base + 4)?;
                for c in 0..4 {
                    s0[c] += wy[b] * cs[c];
                    sy[c] += dy[b] * cs[c];
                }
            }
            for c in 0..4 {
                e0[c] += wx[a] * s0[c];
                ex[c] += dx[a] * s0[c];
                ey[c] += wx[a] * sy[c];
            }
        }
        let dot =
            |u: &[f64; 4], w: &[f64; 4]| (u[0] * w[0] + u[1] * w[1]) + (u[2] * w[2] + u[3] * w[3]);
        let (d, gx, gy, gz) = (dot(&e0, &wz), dot(&ex, &wz), dot(&ey, &wz), dot(&e0, &dz));
        Some((d, DVec3::new(gx, gy, gz) * (1.0 / self.spacing)))
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

/// Cells per reach below which a grid is too coarse for the blend region.
pub const MIN_CELLS_PER_REACH: f64 = 4.0;

/// The tool of `spinal.fields.sdf_tool` from its B-spline coefficients, an array of shape
/// `shape = (nx + 2, ny + 2, nz + 2)` for a distance sampled on `(nx, ny, nz)` nodes,
/// validated: at least 4 nodes per axis, finite vectors, positive spacing and reach, at
/// least [`MIN_CELLS_PER_REACH`] cells per reach, and a support that stays inside the grid
/// ([`GridTool::new`]).
#[allow(clippy::too_many_arguments)]
pub fn grid_tool(
    origin: DVec3,
    spacing: f64,
    shape: [usize; 3],
    coef: Vec<f64>,
    velocity: DVec3,
    center: DVec3,
    reach: f64,
    linear: bool,
    moving: bool,
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
    if let Some(i) = coef.iter().position(|c| !c.is_finite()) {
        return Err(InputError::new(
            "grid",
            format!("spline coefficient {i} is not finite"),
        ));
    }
    let tool = GridTool::new(
        origin, spacing, n, coef, velocity, center, reach, linear, moving,
    )?;
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
    fn shape(&self) -> Option<super::curl::ToolShape> {
        Some(super::curl::ToolShape {
            shape: super::curl::Shape::Grid(std::sync::Arc::new(self.clone())),
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
    /// combination of them), so `|∂d/∂x_a| ≤ max |Δ_a c|/h`.
    pub fn slope_bound(&self) -> f64 {
        let p = [self.n[0] + 2, self.n[1] + 2, self.n[2] + 2];
        let stride = [p[1] * p[2], p[2], 1];
        let mut m = [0.0f64; 3];
        for i in 0..p[0] {
            for j in 0..p[1] {
                for k in 0..p[2] {
                    let at = i * stride[0] + j * stride[1] + k;
                    for (a, idx) in [i, j, k].into_iter().enumerate() {
                        if idx + 1 < p[a] {
                            let diff = (self.coef[at + stride[a]] - self.coef[at]).abs();
                            m[a] = m[a].max(diff);
                        }
                    }
                }
            }
        }
        DVec3::from(m).length() / self.spacing
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Coefficients `c = |node − m|²`: the B-spline is `|X − m|² + 3·(1/3)` (its basis has
    /// variance 1/3 per axis), gradient `2(X − m)`.
    #[test]
    fn quadratic_coefficients_give_the_shifted_paraboloid_and_its_gradient() {
        let n = [10, 11, 12];
        let m = DVec3::new(4.5, 5.0, 5.5);
        let mut coef = Vec::new();
        for i in 0..n[0] + 2 {
            for j in 0..n[1] + 2 {
                for k in 0..n[2] + 2 {
                    let p = DVec3::new(i as f64, j as f64, k as f64) - DVec3::ONE;
                    coef.push((p - m).length_squared());
                }
            }
        }
        let o = DVec3::new(0.1, -0.2, 0.3);
        let g = GridTool::new(o, 1.0, n, coef.clone(), DVec3::X, m, 2.0, false, false)
            .unwrap_or_else(|e| panic!("{e}"));
        for x in [DVec3::new(4.3, 5.1, 5.2), DVec3::new(5.0, 4.5, 6.0)] {
            let (d, n) = g.distance(x + o).unwrap();
            assert!((d - ((x - m).length_squared() + 1.0)).abs() < 1e-13, "{d}");
            assert!((n - 2.0 * (x - m)).length() < 1e-13);
        }
        assert!(g.distance(o + DVec3::new(9.5, 0.0, 0.0)).is_none());
        assert!(g.distance(o - DVec3::new(0.01, 0.0, 0.0)).is_none());
        // a support reaching the boundary is refused
        assert!(GridTool::new(o, 1.0, n, coef, DVec3::X, m, 40.0, false, false).is_err());
    }
}

#[cfg(test)]
mod timing {
    use super::*;

    #[test]
    #[ignore]
    fn time_grid_eval() {
        let n = [64, 64, 64];
        let mut coef = Vec::new();
        for i in 0..n[0] + 2 {
            for j in 0..n[1] + 2 {
                for k in 0..n[2] + 2 {
                    let p = DVec3::new(i as f64, j as f64, k as f64) - DVec3::splat(32.5);
                    coef.push(p.length() * 0.03 - 0.3);
                }
            }
        }
        let g = GridTool::new(
            DVec3::splat(-1.0),
            0.03,
            n,
            coef,
            DVec3::X,
            DVec3::ZERO,
            0.3,
            false,
            false,
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let pts: Vec<DVec3> = (0..1_000_000)
            .map(|i| {
                let a = i as f64 * 0.001;
                DVec3::new(a.sin(), a.cos(), (a * 0.37).sin()) * 0.45
            })
            .collect();
        let t = std::time::Instant::now();
        let mut s = DVec3::ZERO;
        for p in &pts {
            s += g.eval(*p, 0.0);
        }
        println!(
            "grid eval: {} ns/point ({s})",
            t.elapsed().as_secs_f64() / pts.len() as f64 * 1e9
        );
    }
}
