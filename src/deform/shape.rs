//! The tools' shared vocabulary: a shape's signed distance `d` ([`Distance`], [`Shape`]) and
//! von Funck's region function `D = b(d/R_f)`, `v = (1 − D)² u + (1 − D) D′ [(n·u) Y − (n·Y) u]`.

use std::sync::Arc;

use glam::DVec3;

pub use super::{Shape, ToolShape};

/// The signed distance of a tool's shape (negative inside), in the shape's own frame.
pub trait Distance: Send + Sync + std::fmt::Debug {
    /// `(d, ∇d)` at `x`, or `None` where `|d| ≥ reach` is certain (it may also return a
    /// distance with `|d| ≥ reach`, which the falloff zeroes). `∇d` must be the exact
    /// gradient of the `d` returned (it need not be a unit vector).
    fn distance(&self, x: DVec3) -> Option<(f64, DVec3)>;
    /// The reach `R` the shape was built for (the support is `|d| < R`).
    fn reach(&self) -> f64;
    /// The tool's centre `C` (the origin of `Y` for a translation).
    fn center(&self) -> DVec3;
    /// An upper bound of `|X − C|` over the support `|d| < R`.
    fn extent(&self) -> f64;
    /// An upper bound of `|∇d|` over the support (1 for an exact distance).
    fn gradient_bound(&self) -> f64 {
        1.0
    }
    /// Whether an evaluation reads a table at a place that depends on the point (a grid's
    /// coefficients, an axis's segments): see [`super::Tool::wants_locality`].
    fn wants_locality(&self) -> bool {
        false
    }
    /// Whether [`Self::distance`] is certain to be `None` at every point of the box
    /// `[lo, hi]` (checked once for a batch of points; `false` when unsure).
    #[inline(always)]
    fn misses(&self, _lo: DVec3, _hi: DVec3) -> bool {
        false
    }
    /// Whether [`Self::misses`] is worth a test per batch (then the batch's lanes also run
    /// in an AVX2 build where the processor has it).
    fn culls_boxes(&self) -> bool {
        false
    }
}

impl<D: Distance + ?Sized> Distance for Arc<D> {
    #[inline(always)]
    fn distance(&self, x: DVec3) -> Option<(f64, DVec3)> {
        (**self).distance(x)
    }
    fn reach(&self) -> f64 {
        (**self).reach()
    }
    fn center(&self) -> DVec3 {
        (**self).center()
    }
    fn extent(&self) -> f64 {
        (**self).extent()
    }
    fn gradient_bound(&self) -> f64 {
        (**self).gradient_bound()
    }
    fn wants_locality(&self) -> bool {
        (**self).wants_locality()
    }
    #[inline(always)]
    fn misses(&self, lo: DVec3, hi: DVec3) -> bool {
        (**self).misses(lo, hi)
    }
    #[inline(always)]
    fn culls_boxes(&self) -> bool {
        (**self).culls_boxes()
    }
}

/// A ball: `d = |X − c| − ρ`, `∇d = (X − c)/|X − c|` (zero at the centre).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ball {
    pub center: DVec3,
    pub radius: f64,
    pub reach: f64,
}

impl Distance for Ball {
    #[inline(always)]
    fn distance(&self, x: DVec3) -> Option<(f64, DVec3)> {
        let y = x - self.center;
        let r2 = y.length_squared();
        if outside_shell(r2, self.radius, self.reach) {
            return None;
        }
        Some(radial(y, r2.sqrt(), self.radius))
    }
    fn reach(&self) -> f64 {
        self.reach
    }
    fn center(&self) -> DVec3 {
        self.center
    }
    fn extent(&self) -> f64 {
        self.radius + self.reach
    }
}

/// A torus about the unit `axis` through `center` (major radius `R_t`, tube radius `r_t`):
/// `d = √((ρ − R_t)² + z²) − r_t` with `z = k·Y`, `ρ = |Y − z k|`, `Y = X − center`, and
/// `∇d = ((ρ − R_t) e_ρ + z k)/√((ρ − R_t)² + z²)` (zero on the core circle). Smooth in the
/// support `|d| < R` when `r_t + R < R_t` (away from the axis and the core circle's inside).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ring {
    pub center: DVec3,
    pub axis: DVec3,
    pub major: f64,
    pub minor: f64,
    pub reach: f64,
}

impl Distance for Ring {
    #[inline(always)]
    fn distance(&self, x: DVec3) -> Option<(f64, DVec3)> {
        let y = x - self.center;
        let z = self.axis.dot(y);
        let yp = y - self.axis * z;
        let rho = yp.length();
        let dr = rho - self.major;
        let dist = (dr * dr + z * z).sqrt();
        let d = dist - self.minor;
        if !(d.abs() < self.reach) || !(rho > 0.0) {
            return None;
        }
        let g = if dist > 0.0 {
            (yp * (dr / rho) + self.axis * z) * (1.0 / dist)
        } else {
            DVec3::ZERO
        };
        Some((d, g))
    }
    fn reach(&self) -> f64 {
        self.reach
    }
    fn center(&self) -> DVec3 {
        self.center
    }
    fn extent(&self) -> f64 {
        self.major + self.minor + self.reach
    }
}

/// `(D, D′)` of the region function at signed distance `d`, reach `rf`.
#[inline(always)]
pub(crate) fn blend(d: f64, rf: f64, linear: bool) -> (f64, f64) {
    let s = d / rf;
    if !(s > 0.0) {
        (0.0, 0.0)
    } else if !(s < 1.0) {
        (1.0, 0.0)
    } else if linear {
        (s, 1.0 / rf)
    } else {
        (s * s * s * (4.0 - 3.0 * s), 12.0 * s * s * (1.0 - s) / rf)
    }
}

/// The translation field from `d`, `n`, `Y = X − c`, `u` (`None` outside the support).
#[inline(always)]
pub(crate) fn translate(d: f64, n: DVec3, y: DVec3, u: DVec3, rf: f64, linear: bool) -> DVec3 {
    if !(d < rf) {
        return DVec3::ZERO;
    }
    if !(d > 0.0) {
        return u;
    }
    let (b, db) = blend(d, rf, linear);
    let g = 1.0 - b;
    (g * g) * u + (g * db) * (y * n.dot(u) - u * n.dot(y))
}

/// `max_σ [(1 − D)² + (1 − D) D′ L(σ)]` sampled on 2049 distances, `L(σ)` a bound of `|Y|`
/// (a sampled maximum is low by O(spacing²), immaterial for a step-size rule).
pub(crate) fn speed_factor(rf: f64, linear: bool, l: impl Fn(f64) -> f64) -> f64 {
    let n = 2048;
    let mut m: f64 = 1.0;
    for i in 0..=n {
        let d = rf * i as f64 / n as f64;
        let (b, db) = blend(d, rf, linear);
        let g = 1.0 - b;
        m = m.max(g * g + g * db * l(d));
    }
    m
}

/// `((R − |d|)/R)^(p−1)` and `e = R − |d|` for `|d| < R`, `None` outside the support. The
/// factor `e^{p−1}/R^p` of the curl fields ([`super::fields`], [`super::curl::Falloff`]) is the first value over `R`: written with the
/// ratio `e/R ∈ (0, 1]`, it neither overflows nor underflows at any scale of the tool.
#[inline(always)]
pub(crate) fn falloff_ratio(d: f64, reach: f64, p: u8) -> Option<(f64, f64)> {
    let e = reach - d.abs();
    if !(e > 0.0) {
        return None;
    }
    let q = e / reach;
    let qp = match p {
        2 => q,
        3 => q * q,
        _ => q * q * q,
    };
    Some((qp, e))
}

/// `|Y|² = r2` lies outside the shell `ρ − R < |Y| < ρ + R` (a test without a square root, so
/// points far from the tool cost a few multiplications).
#[inline(always)]
pub(crate) fn outside_shell(r2: f64, rho: f64, reach: f64) -> bool {
    let outer = rho + reach;
    let inner = rho - reach;
    !(r2 < outer * outer) || (inner > 0.0 && r2 <= inner * inner)
}

/// The signed distance `r − ρ` from a sphere (or a tube about an axis) of radius `ρ` of a
/// point at `y` from its centre (its nearest axis point), `r = |y|`, and its gradient
/// `y/r` (zero at the centre).
#[inline(always)]
pub(crate) fn radial(y: DVec3, r: f64, rho: f64) -> (f64, DVec3) {
    let g = if r > 0.0 { y * (1.0 / r) } else { DVec3::ZERO };
    (r - rho, g)
}

/// A point `c` of a tool carried with its velocity `u` at time `t` (`c + u t`) when the tool
/// moves, else `c`.
#[inline(always)]
pub(crate) fn moved(c: DVec3, u: DVec3, moving: bool, t: f64) -> DVec3 {
    if moving { c + u * t } else { c }
}
