//! Spatial Pythagorean-hodograph (PH) cubics (Mäurer & Jüttler, "Rational approximation of
//! rotation minimizing frames using Pythagorean-hodograph cubics", Journal for Geometry and
//! Graphics 3, 1999, §3; "MJ" below, with its equation numbers; see docs/references.md).
//!
//! A cubic Bézier curve `x(v) = Σ bᵢ Bᵢ³(v)`, `v ∈ [0, 1]`, is PH when its speed
//! `σ = |ẋ|` is a polynomial. Every spatial PH cubic comes from a linear quaternion
//! polynomial `A(v) = A₀(1 − v) + A₁ v` as `ẋ = A i A*`, so `σ = |A|²` (quadratic). With
//! `dᵢ = bᵢ − bᵢ₋₁`, `Lᵢ = |dᵢ|`, `cθ = d₁·d₂/(L₁L₂)`, `Δ = det[d₁, d₂, d₃]`:
//!
//! * `σ(v) = 3(c v² − 2b v + L₁)` with `a = √(L₁L₃ − L₂²cθ²)`, `b = L₁ − L₂cθ`,
//!   `c = L₁ − 2L₂cθ + L₃`;
//! * `κ = 6L₂sθ/σ²`, `τ = sgn(Δ)·6√(L₁L₃ − L₂²)/σ²`, κ/τ constant (MJ (18) writes
//!   `τ = −3L₁L₃ sin ψ/(L₂σ²)` with ψ "the angle between" two vectors, which is unsigned; the
//!   torsion needs the sign, `sgn(sin ψ) = −sgn(Δ)`, as the standard `det[ẋ, ẍ, x⃛]/|ẋ × ẍ|²`
//!   confirms);
//! * `k = −sgn(Δ)√(L₁L₃ − L₂²)/a` (|k| ≤ 1; 0 for planar cubics), the factor of the exact
//!   rotation-minimising angle ([`frame`]).
//!
//! Submodules: [`check`] (value checks of the input), [`hermite`] (G¹ Hermite interpolation with the corrected, signed equation) and
//! [`frame`] (Frenet frame, exact RMF angle, its rational approximation).

pub mod check;
pub mod frame;
pub mod hermite;

use glam::DVec3;

use crate::error::{InputError, Result};
use crate::run::alloc;
use crate::run::cancel::{self, Cancel};

use crate::math::cubic::Bezier;
pub use crate::math::cubic::bern2;

/// A quaternion `(w, x, y, z)` (Hamilton product).
pub type Quat = [f64; 4];

/// Hamilton product `a b`.
pub fn qmul(a: Quat, b: Quat) -> Quat {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

fn qconj(a: Quat) -> Quat {
    [a[0], -a[1], -a[2], -a[3]]
}

const QI: Quat = [0.0, 1.0, 0.0, 0.0];

/// Vector part of `a i b*`.
fn aib(a: Quat, b: Quat) -> DVec3 {
    let q = qmul(qmul(a, QI), qconj(b));
    DVec3::new(q[1], q[2], q[3])
}

fn qscale(a: Quat, s: f64) -> Quat {
    [a[0] * s, a[1] * s, a[2] * s, a[3] * s]
}

/// A cubic Bézier curve by its four control points (evaluated by [`Bezier`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cubic {
    /// Control points `b₀ … b₃`.
    pub b: [DVec3; 4],
}

/// The scalar invariants of a PH cubic (meaningful only for PH control polygons).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Invariants {
    /// Leg lengths `L₁, L₂, L₃` of the control polygon, `Lᵢ = |bᵢ − bᵢ₋₁|`.
    pub l: [f64; 3],
    pub ctheta: f64,
    pub stheta: f64,
    /// `Δ = det[d₁, d₂, d₃]` of the legs (its sign is the sign of the torsion).
    pub delta: f64,
    /// `a = √(L₁L₃ − L₂²cθ²)` of the speed `σ(v) = 3(c v² − 2b v + L₁)`.
    pub a: f64,
    /// `b = L₁ − L₂cθ` of the speed.
    pub b: f64,
    /// `c = L₁ − 2L₂cθ + L₃` of the speed.
    pub c: f64,
    /// `k = −sgn(Δ)√(L₁L₃ − L₂²)/a` (|k| ≤ 1; 0 for planar cubics), the factor of the RMF angle.
    pub k: f64,
    /// `κ/τ` (constant along a PH cubic; ±∞ for planar ones).
    pub kappa_over_tau: f64,
    pub sigma_min: f64,
    pub kappa_max: f64,
}

impl Invariants {
    /// Index of `κ/τ` in [`Invariants::row`] (infinite for a planar cubic; every other entry
    /// is finite for a PH cubic that is not straight).
    pub const KAPPA_OVER_TAU: usize = 10;

    /// `[L1, L2, L3, cθ, sθ, Δ, a, b, c, k, κ/τ, σ_min, κ_max]`, the order of
    /// `spinal.ph.invariants`.
    pub fn row(&self) -> [f64; 13] {
        [
            self.l[0],
            self.l[1],
            self.l[2],
            self.ctheta,
            self.stheta,
            self.delta,
            self.a,
            self.b,
            self.c,
            self.k,
            self.kappa_over_tau,
            self.sigma_min,
            self.kappa_max,
        ]
    }
}

/// Relative size of `sθ` below which a cubic counts as a straight segment.
pub const STRAIGHT_EPS: f64 = 1e-12;

impl Cubic {
    pub fn new(b: [DVec3; 4]) -> Self {
        Cubic { b }
    }

    /// The curve as a [`Bezier`] (its evaluation kernels).
    #[inline]
    pub fn bezier(&self) -> Bezier {
        Bezier::new(self.b)
    }

    /// The legs `bᵢ − bᵢ₋₁`.
    pub fn legs(&self) -> [DVec3; 3] {
        self.bezier().legs()
    }

    /// Point `x(v)` (de Casteljau).
    pub fn point(&self, v: f64) -> DVec3 {
        self.bezier().point(v)
    }

    /// `ẋ(v) = 3 Σ dᵢ Bᵢ²(v)`.
    pub fn d1(&self, v: f64) -> DVec3 {
        self.bezier().d1(v)
    }

    /// `ẍ(v) = 6((d₂ − d₁)(1 − v) + (d₃ − d₂)v)`.
    pub fn d2(&self, v: f64) -> DVec3 {
        self.bezier().d2(v)
    }

    /// `x⃛ = 6(d₃ − 2d₂ + d₁)`.
    pub fn d3(&self) -> DVec3 {
        self.bezier().d3()
    }

    /// Derivative of order `k` (0..=3) at `v` (zero above 3).
    pub fn derivative(&self, k: usize, v: f64) -> DVec3 {
        self.bezier().derivative(k, v)
    }

    /// True when the control polygon is (numerically) a straight line run forwards.
    pub fn is_straight(&self) -> bool {
        let [d1, d2, d3] = self.legs();
        let (l1, l2, l3) = (d1.length(), d2.length(), d3.length());
        l1 > 0.0
            && l2 > 0.0
            && l3 > 0.0
            && d1.cross(d2).length() <= STRAIGHT_EPS * l1 * l2
            && d2.cross(d3).length() <= STRAIGHT_EPS * l2 * l3
            && d1.dot(d2) > 0.0
            && d2.dot(d3) > 0.0
    }

    /// Invariants of MJ (18), (31) (the cubic is assumed PH).
    ///
    /// Evaluated for accuracy on nearly straight cubics, where `L₁L₃ − L₂²`, `L₁ − L₂cθ`
    /// and `L₁ − 2L₂cθ + L₃` would cancel: `sgn(Δ)√(L₁L₃ − L₂²)` from the preimage
    /// ([`twist`]), `a² = (L₁L₃ − L₂²) + L₂²sθ²`, `b = d₁·(d₁ − d₂)/L₁`,
    /// `c = (a² + b²)/L₁` (from `σ(0) = 3L₁`).
    pub fn invariants(&self) -> Invariants {
        let [d1, d2, d3] = self.legs();
        let l = [d1.length(), d2.length(), d3.length()];
        let cr = d1.cross(d2);
        let cr2 = cr.length_squared();
        let ctheta = d1.dot(d2) / (l[0] * l[1]);
        let stheta = cr2.sqrt() / (l[0] * l[1]);
        let delta = cr.dot(d3);
        let l2s = cr2.sqrt() / l[0]; // L₂ sθ
        // sgn(Δ)√(L₁L₃ − L₂²) from the preimage (`twist`); the lengths formula and Δ lose
        // digits on nearly straight cubics. 0 for planar cubics (at round-off).
        let signed = match self.preimage() {
            Some((a0, a1, _)) => twist(a0, a1),
            None => delta.signum() * (l[0] * l[2] - l[1] * l[1]).max(0.0).sqrt(),
        };
        let root = if signed.abs() > 1e-13 * (l[0] * l[2]).sqrt() {
            signed.abs()
        } else {
            0.0
        };
        let a = root.hypot(l2s);
        let b = d1.dot(d1 - d2) / l[0];
        let c = (a * a + b * b) / l[0];
        let sgn = if root > 0.0 { signed.signum() } else { 0.0 };
        let k = if a > 0.0 { -sgn * root / a } else { 0.0 };
        let kappa_over_tau = if root > 0.0 {
            sgn * l2s / root
        } else {
            f64::INFINITY
        };
        let vm = if c > 0.0 { b / c } else { -1.0 };
        let sigma_min = if (0.0..=1.0).contains(&vm) {
            3.0 * a * a / c
        } else {
            3.0 * l[0].min(l[2])
        };
        let kappa_max = 6.0 * l2s / (sigma_min * sigma_min);
        Invariants {
            l,
            ctheta,
            stheta,
            delta,
            a,
            b,
            c,
            k,
            kappa_over_tau,
            sigma_min,
            kappa_max,
        }
    }

    /// Control-polygon PH test (MJ (17)): `θ₁₂ = θ₂₃` and `cos ψ = 2L₂²/(L₁L₃) − 1`, each
    /// within `tol` (dimensionless). Polygons with a zero leg are not PH cubics here; a
    /// straight polygon run forwards is PH iff `L₂² ≤ L₁L₃` (then it has a quaternion
    /// preimage); a planar bent polygon iff the angles agree and `L₂² = L₁L₃` (convex).
    pub fn is_ph(&self, tol: f64) -> bool {
        let [d1, d2, d3] = self.legs();
        let (l1, l2, l3) = (d1.length(), d2.length(), d3.length());
        if !(l1 > 0.0 && l2 > 0.0 && l3 > 0.0 && (l1 + l2 + l3).is_finite()) {
            return false;
        }
        let c12 = d1.dot(d2) / (l1 * l2);
        let c23 = d2.dot(d3) / (l2 * l3);
        if !((c12 - c23).abs() <= tol) {
            return false;
        }
        let target = 2.0 * l2 * l2 / (l1 * l3) - 1.0;
        let n12 = d1.cross(d2);
        let n23 = d2.cross(d3);
        let (m12, m23) = (n12.length(), n23.length());
        let planar_eps = 1e-12;
        if m12 <= planar_eps * l1 * l2 && m23 <= planar_eps * l2 * l3 {
            // straight: forward legs; the preimage exists iff L₂² ≤ L₁L₃
            return c12 > 0.0 && target <= 1.0 + tol;
        }
        if m12 <= planar_eps * l1 * l2 || m23 <= planar_eps * l2 * l3 {
            return false; // one bend only: the angle test cannot really pass
        }
        let cpsi = n12.dot(n23) / (m12 * m23);
        (cpsi - target).abs() <= tol
    }

    /// Control points from a quaternion preimage `A₀, A₁` and the start point (the quaternion
    /// form of spatial PH curves; MJ characterise PH cubics by their control polygon, (17)).
    ///
    /// The legs are quadratic in `A`: both quaternions are divided by the power of two `2^k`
    /// nearest their largest component first and the legs multiplied by `2^{2k}` after, so
    /// the intermediate products cannot overflow where the legs themselves fit in f64 (a leg
    /// beyond the f64 range is ±inf: callers check).
    pub fn from_quaternions(a0: Quat, a1: Quat, start: DVec3) -> Self {
        use crate::math::scale::{exponent, ldexp};
        let m = a0
            .iter()
            .chain(a1.iter())
            .fold(0.0_f64, |m, c| m.max(c.abs()));
        let k = if m > 0.0 && m.is_finite() {
            exponent(m)
        } else {
            0
        };
        let (a0, a1) = (a0.map(|c| ldexp(c, -k)), a1.map(|c| ldexp(c, -k)));
        let back = |v: DVec3| DVec3::new(ldexp(v.x, 2 * k), ldexp(v.y, 2 * k), ldexp(v.z, 2 * k));
        let b0 = start;
        let b1 = b0 + back(aib(a0, a0) / 3.0);
        let b2 = b1 + back((aib(a0, a1) + aib(a1, a0)) / 6.0);
        let b3 = b2 + back(aib(a1, a1) / 3.0);
        Cubic::new([b0, b1, b2, b3])
    }

    /// Quaternion preimage `(A₀, A₁)` and the residual `max |regenerated bᵢ − bᵢ|` (the PH
    /// defect; 0 up to round-off for PH cubics). `None` when a leg has zero length.
    pub fn preimage(&self) -> Option<(Quat, Quat, f64)> {
        let [d1, d2, d3] = self.legs();
        let a0 = root(3.0 * d1)?;
        let a10 = root(3.0 * d3)?;
        let x = (aib(a0, a10) + aib(a10, a0)) / 6.0;
        let a1i = qmul(a10, QI);
        let y = (aib(a0, a1i) + aib(a1i, a0)) / 6.0;
        // least squares [x y] (cφ, sφ)ᵀ = d₂
        let (xx, xy, yy) = (x.dot(x), x.dot(y), y.dot(y));
        let (xd, yd) = (x.dot(d2), y.dot(d2));
        let det = xx * yy - xy * xy;
        let (mut cp, mut sp) = if det.abs() > 1e-300 {
            ((yy * xd - xy * yd) / det, (xx * yd - xy * xd) / det)
        } else {
            (1.0, 0.0)
        };
        let n = cp.hypot(sp);
        if n > 0.0 {
            cp /= n;
            sp /= n;
        } else {
            (cp, sp) = (1.0, 0.0);
        }
        let a1 = qmul(a10, [cp, sp, 0.0, 0.0]);
        let back = Cubic::from_quaternions(a0, a1, self.b[0]);
        let res = (0..4)
            .map(|i| (back.b[i] - self.b[i]).length())
            .fold(0.0, f64::max);
        Some((a0, a1, res))
    }
}

/// The quaternion `A` with `A i A* = d` (one of the circle of solutions), or None for d = 0.
fn root(d: DVec3) -> Option<Quat> {
    let len = d.length();
    if !(len > 0.0) || !len.is_finite() {
        return None;
    }
    let e = d / len;
    let u = if e.x > -0.5 {
        [1.0 + e.x, 0.0, -e.z, e.y]
    } else {
        // j maps x̂ to −x̂ first: u = normalize(1 − δx, −x̂×δ)·j
        qmul([1.0 - e.x, 0.0, e.z, -e.y], [0.0, 0.0, 1.0, 0.0])
    };
    let n = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2] + u[3] * u[3]).sqrt();
    Some(qscale(u, len.sqrt() / n))
}

/// `sgn(Δ)·√(L₁L₃ − L₂²)` of the PH cubic with preimage `A₀, A₁` (= `K/3`,
/// `K = u₀v₁ − u₁v₀ − p₀q₁ + p₁q₀` for `A = (u, v, p, q)`). Polynomial in the preimage, so
/// well conditioned where the lengths formula and `Δ` cancel (nearly straight cubics).
pub fn twist(a0: Quat, a1: Quat) -> f64 {
    (a0[0] * a1[1] - a1[0] * a0[1] - a0[2] * a1[3] + a1[2] * a0[3]) / 3.0
}

/// The Euler–Rodrigues frame `(t, e₂, e₃)` at `v`: the columns of the rotation `R(A(v))`.
/// On a PH cubic it is the Frenet frame turned about `t` by a constant angle. None where
/// `A(v)` vanishes (a cusp).
pub fn erf(a0: Quat, a1: Quat, v: f64) -> Option<(DVec3, DVec3, DVec3)> {
    let q: Quat = std::array::from_fn(|i| a0[i] * (1.0 - v) + a1[i] * v);
    let n2 = q.iter().map(|x| x * x).sum::<f64>();
    if !(n2 > 1e-300) || !n2.is_finite() {
        return None;
    }
    let (w, x, y, z) = (q[0], q[1], q[2], q[3]);
    let t = DVec3::new(
        w * w + x * x - y * y - z * z,
        2.0 * (x * y + w * z),
        2.0 * (x * z - w * y),
    );
    let e2 = DVec3::new(
        2.0 * (x * y - w * z),
        w * w - x * x + y * y - z * z,
        2.0 * (y * z + w * x),
    );
    let e3 = DVec3::new(
        2.0 * (x * z + w * y),
        2.0 * (y * z - w * x),
        w * w - x * x - y * y + z * z,
    );
    Some((t / n2, e2 / n2, e3 / n2))
}

/// Segment index and local parameter `v` of the global spline parameter `s = segment + v`
/// on `m ≥ 1` segments (`s = m` is the end of the last segment, `v = 1`).
pub fn locate(m: usize, s: f64) -> (usize, f64) {
    let seg = (s.floor().max(0.0) as usize).min(m - 1);
    (seg, s - seg as f64)
}

/// Check global parameters `s` of a spline of `m` segments: at least one segment, every
/// value finite and within `[0, m]`.
///
/// Scans `s` in parallel blocks that poll `cancel` (a stopped check passes; see
/// [`crate::run::cancel`]).
pub fn check_params(m: usize, s: &[f64], cancel: Cancel<'_>) -> Result<()> {
    if m == 0 {
        return Err(InputError::new("control_points", "no segments"));
    }
    let inside = |x: &f64| x.is_finite() && *x >= 0.0 && *x <= m as f64;
    if crate::frames::validate::first_bad(s, inside, cancel).is_some() {
        return Err(InputError::new(
            "s",
            format!("values must be finite and within [0, {m}]"),
        ));
    }
    Ok(())
}

/// Points (`derivative = 0`) or derivatives of order 1..=3 with respect to the local `v`
/// of the spline `cubics` at the global parameters `s` (see [`locate`]), in parallel.
pub fn eval_at(cubics: &[Cubic], s: &[f64], derivative: usize) -> Result<Vec<DVec3>> {
    let mut out = alloc::filled("PHSpline.evaluate", s.len(), DVec3::ZERO)?;
    eval_into(cubics, s, derivative, &mut out, &cancel::never)?;
    Ok(out)
}

/// [`eval_at`] into `out` (one row per parameter), polling `cancel` in the checks and
/// between blocks of rows (`out` incomplete once it says stop; see [`crate::run::cancel`]).
pub fn eval_into(
    cubics: &[Cubic],
    s: &[f64],
    derivative: usize,
    out: &mut [DVec3],
    cancel: Cancel<'_>,
) -> Result<()> {
    check_params(cubics.len(), s, cancel)?;
    check::finite_cubics(cubics)?;
    if derivative > 3 {
        return Err(InputError::new(
            "derivative",
            format!("must be 0, 1, 2 or 3, got {derivative}"),
        ));
    }
    if out.len() != s.len() {
        return Err(InputError::new("out", "output buffer has the wrong size"));
    }
    cancel::fill(out, cancel, |j| {
        let (i, v) = locate(cubics.len(), s[j]);
        cubics[i].derivative(derivative, v)
    });
    Ok(())
}

/// [`Cubic::from_quaternions`] row by row (preimages scalar first).
pub fn from_quaternion_rows(a0: &[Quat], a1: &[Quat], start: &[DVec3]) -> Result<Vec<Cubic>> {
    const CALL: &str = "ph.from_quaternions";
    let mut out = alloc::filled(CALL, a0.len(), [0.0; 12])?;
    from_quaternion_rows_into(a0, a1, start, true, &mut out, &cancel::never)?;
    alloc::collect(
        CALL,
        out.iter()
            .map(|r| Cubic::new([0, 3, 6, 9].map(|k| DVec3::new(r[k], r[k + 1], r[k + 2])))),
    )
}

/// [`Cubic::from_quaternions`] row by row into `out` (one row `[b₀, b₁, b₂, b₃]` per pair of
/// preimages): `a0`, `a1` scalar first, or `(x, y, z, w)` when not `scalar_first`; `start`
/// holds one point for every row or one per row. Polls `cancel` in the checks and between
/// blocks of rows (`out` incomplete once it says stop; see [`crate::run::cancel`]).
pub fn from_quaternion_rows_into(
    a0: &[Quat],
    a1: &[Quat],
    start: &[DVec3],
    scalar_first: bool,
    out: &mut [[f64; 12]],
    cancel: Cancel<'_>,
) -> Result<()> {
    let m = a0.len();
    if a1.len() != m || !(start.len() == m || start.len() == 1) {
        return Err(InputError::new(
            "A0, A1, start",
            "must have the same number of rows (or one start)",
        ));
    }
    if out.len() != m {
        return Err(InputError::new("out", "output buffer has the wrong size"));
    }
    let finite = |arg: &'static str, rows: &[Quat]| {
        let bad =
            crate::frames::validate::first_bad(rows, |r| r.iter().all(|x| x.is_finite()), cancel);
        bad.map_or(Ok(()), |i| {
            Err(InputError::new(
                arg,
                format!("contains non-finite values (in row {i})"),
            ))
        })
    };
    finite("A0", a0)?;
    finite("A1", a1)?;
    if let Some(i) = start.iter().position(|p| !p.is_finite()) {
        return Err(InputError::new(
            "start",
            format!("contains non-finite values (in row {i})"),
        ));
    }
    let order = |q: Quat| {
        if scalar_first {
            q
        } else {
            [q[3], q[0], q[1], q[2]]
        }
    };
    let row = |i: usize| {
        let p = start[if start.len() == 1 { 0 } else { i }];
        let c = Cubic::from_quaternions(order(a0[i]), order(a1[i]), p);
        let mut r = [0.0; 12];
        for (k, b) in c.b.iter().enumerate() {
            r[3 * k..3 * k + 3].copy_from_slice(&b.to_array());
        }
        r
    };
    if !cancel::fill(out, cancel, row) {
        return Ok(());
    }
    let inside = |r: &[f64; 12]| r.iter().all(|x| x.is_finite());
    match crate::frames::validate::first_bad(out, inside, cancel) {
        None => Ok(()),
        Some(i) => Err(InputError::new(
            "A0, A1",
            format!(
                "row {i}: the control points (of size |A|² plus start) are out of the \
                 representable range of float64"
            ),
        )),
    }
}

/// [`Cubic::preimage`] of every cubic as a row `[A₀ (4), A₁ (4), residual]`; a cubic with a
/// zero-length leg, or whose residual exceeds `tol` times the length of its control polygon
/// (not PH), is an error naming it (`batch`: with its index).
///
/// Polls `cancel` between blocks of cubics (an incomplete result once it says stop; see
/// [`crate::run::cancel`]).
pub fn preimage_rows(
    cubics: &[Cubic],
    tol: f64,
    batch: bool,
    cancel: crate::run::cancel::Cancel<'_>,
) -> Result<Vec<[f64; 9]>> {
    check::finite_cubics(cubics)?;
    alloc::try_collect(
        "ph.preimage",
        cubics.iter().enumerate().map(|(i, c)| {
            let (q0, q1, res) = c.preimage().ok_or_else(|| {
                InputError::new(
                    "control_points",
                    format!("cubic {i} has a control-polygon leg of zero length (not a PH cubic)"),
                )
            })?;
            let scale: f64 = c.legs().iter().map(|d| d.length()).sum();
            if !(res <= tol * scale) {
                let at = if batch {
                    format!("cubic {i}: ")
                } else {
                    String::new()
                };
                return Err(InputError::new(
                    "control_points",
                    format!(
                        "{at}not a PH cubic (preimage residual {res:.3e} for a polygon of \
                         length {scale:.3e})"
                    ),
                ));
            }
            Ok([q0[0], q0[1], q0[2], q0[3], q1[0], q1[1], q1[2], q1[3], res])
        }),
        cancel,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quaternion_round_trip() {
        let a0 = [0.3, -1.2, 0.7, 0.4];
        let a1 = [-0.5, 0.2, 1.1, -0.9];
        let c = Cubic::from_quaternions(a0, a1, DVec3::new(1.0, 2.0, 3.0));
        assert!(c.is_ph(1e-9));
        let (_, _, res) = c.preimage().unwrap();
        assert!(res < 1e-12, "{res}");
        // σ = |A|² at v = 0.3
        let v = 0.3;
        let a: Vec<f64> = (0..4).map(|i| a0[i] * (1.0 - v) + a1[i] * v).collect();
        let s2: f64 = a.iter().map(|x| x * x).sum();
        assert!((c.d1(v).length() - s2).abs() < 1e-12);
    }

    #[test]
    fn root_covers_both_branches() {
        for d in [DVec3::X, -DVec3::X, DVec3::new(-0.9, 0.1, 0.2), DVec3::Y] {
            let a = root(d).unwrap();
            assert!((aib(a, a) - d).length() < 1e-15);
        }
    }

    fn two_segments() -> Vec<Cubic> {
        let a = Cubic::from_quaternions([0.3, -1.2, 0.7, 0.4], [-0.5, 0.2, 1.1, -0.9], DVec3::ZERO);
        let b = Cubic::from_quaternions([1.0, 0.2, -0.3, 0.1], [0.4, 0.9, 0.2, -0.6], a.b[3]);
        vec![a, b]
    }

    #[test]
    fn eval_at_locates_segments_and_checks_parameters() {
        let c = two_segments();
        let s = [0.0, 0.25, 1.0, 1.5, 2.0];
        for d in 0..4 {
            let got = eval_at(&c, &s, d).unwrap();
            let want = [
                c[0].derivative(d, 0.0),
                c[0].derivative(d, 0.25),
                c[1].derivative(d, 0.0),
                c[1].derivative(d, 0.5),
                c[1].derivative(d, 1.0),
            ];
            assert_eq!(got, want);
        }
        assert_eq!(locate(2, 2.0), (1, 1.0));
        let e = eval_at(&c, &[2.5], 0).unwrap_err();
        assert_eq!(e.to_string(), "s: values must be finite and within [0, 2]");
        assert!(eval_at(&c, &[f64::NAN], 0).is_err());
        let e = eval_at(&c, &[0.5], 4).unwrap_err();
        assert_eq!(e.to_string(), "derivative: must be 0, 1, 2 or 3, got 4");
        let mut nan = c.clone();
        nan[0].b[1].x = f64::NAN;
        let e = eval_at(&nan, &[0.5], 0).unwrap_err();
        assert_eq!(e.arg, "control_points");
        let e = eval_at(&[], &[0.0], 0).unwrap_err();
        assert_eq!(e.to_string(), "control_points: no segments");
    }

    #[test]
    fn quaternion_rows_round_trip() {
        let c = two_segments();
        let rows = preimage_rows(&c, 1e-9, true, &cancel::never).unwrap();
        let a0: Vec<Quat> = rows.iter().map(|r| [r[0], r[1], r[2], r[3]]).collect();
        let a1: Vec<Quat> = rows.iter().map(|r| [r[4], r[5], r[6], r[7]]).collect();
        assert!(rows.iter().all(|r| r[8] < 1e-12));
        let back = from_quaternion_rows(&a0, &a1, &[c[0].b[0], c[1].b[0]]).unwrap();
        for (x, y) in back.iter().zip(&c) {
            for k in 0..4 {
                assert!((x.b[k] - y.b[k]).length() < 1e-12);
            }
        }
        let e = from_quaternion_rows(&a0, &a1[..1], &[DVec3::ZERO; 2]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "A0, A1, start: must have the same number of rows (or one start)"
        );
        // one start for every row: the cubics of each row's own start
        let from_origin = from_quaternion_rows(&a0, &a1, &[DVec3::ZERO]).unwrap();
        for (i, x) in from_origin.iter().enumerate() {
            assert_eq!(x.b, Cubic::from_quaternions(a0[i], a1[i], DVec3::ZERO).b);
        }
        let e = from_quaternion_rows(&a0, &a1, &[DVec3::ZERO; 3]).unwrap_err();
        assert_eq!(e.arg, "A0, A1, start");
        let flat = Cubic::new([DVec3::ZERO, DVec3::ZERO, DVec3::X, DVec3::Y]);
        let e = preimage_rows(&[c[0], flat], 1e-9, true, &cancel::never).unwrap_err();
        assert!(
            e.to_string().starts_with("control_points: cubic 1 has"),
            "{e}"
        );
        // not PH: the residual names the cubic (batch) or not (one cubic)
        let mut bent = c[1];
        bent.b[1] += DVec3::new(0.0, 0.01, 0.0);
        let e = preimage_rows(&[c[0], bent], 1e-9, true, &cancel::never).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("control_points: cubic 1: not a PH cubic"),
            "{e}"
        );
        let e = preimage_rows(&[bent], 1e-9, false, &cancel::never).unwrap_err();
        assert!(
            e.to_string().starts_with("control_points: not a PH cubic"),
            "{e}"
        );
        let e = from_quaternion_rows(&a0, &a1, &[DVec3::ZERO, DVec3::NAN]).unwrap_err();
        assert_eq!(e.arg, "start");
        let mut q = a1.clone();
        q[0][2] = f64::INFINITY;
        let e = from_quaternion_rows(&a0, &q, &[DVec3::ZERO; 2]).unwrap_err();
        assert_eq!(e.arg, "A1");
    }
}
