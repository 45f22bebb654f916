//! Frames on PH cubics (Mäurer & Jüttler 1999, §3.3–§3.4; "MJ" below, with its equation
//! numbers). The sign of the angle follows the signed torsion (see the parent module); MJ (30)
//! leaves an integration constant `Ω₀` that is not `Ω(0)`, so we write the angle with `Ω(0)`
//! explicitly. The propagation along a spline and the fit of `λ` are ours: the paper gives
//! neither.
//!
//! * Rational Frenet frame: `t = ẋ/σ`, `b ∥ ẋ × ẍ`, `n = b × t` (spinal frame `(n, b, t)`).
//! * Exact rotation-minimising angle: the RMF reference vector is
//!   `f₂ = sin Ω b + cos Ω n` (angle from `n` towards `b`) with `Ω̇ = −τσ`, on a PH cubic
//!   `Ω(v) = Ω(0) + 2k[arctan((cv − b)/a) + arctan(b/a)]`.
//! * Rational approximation: with `sg = sign k` and the offset `φ` (default centred,
//!   `(Ω(0) + Ω(1))/2`), `w = sg·tan((Ω − φ)/2)` is replaced by the rational quadratic
//!   Hermite interpolant `W_λ` of its end values and slopes (MJ (36)–(37)); the free `λ`
//!   minimises `Î(λ) = ∫₀¹ (2W′/(1 + W²) − sg Ω̇)² dv` (Simpson, 20 subintervals) over
//!   `λ > λ* = s₀/(w₁ − w₀) − 2` (no pole, W′ > 0). The approximate angle is
//!   `Ω̃ = φ + 2 sg arctan W`, so `cos Ω̃`, `sin Ω̃` and the frame are rational (degree 6).
//!
//! Along a spline the start angle of each segment is taken from the exact end vector of the
//! previous one (both the exact and the rational frame interpolate it), straight segments
//! carry the reference vector unchanged.
//!
//! Conditioning: on nearly straight cubics `ẋ × ẍ` and the torsion lose ~1/θ² digits
//! (θ the turn of the control polygon), so `n, b` are evaluated as the Euler–Rodrigues frame
//! of the quaternion preimage, `R(A(v)/|A(v)|)`, which on a PH cubic is the Frenet frame
//! turned by a constant `β` (any error in `β` cancels, the start angle is measured in the same
//! frame), and `Ω̇ = −2K/σ` uses `K/3 = sgn(Δ)√(L₁L₃ − L₂²)` from the preimage
//! ([`super::twist`]).

use glam::{DMat3, DVec3};

use super::{Cubic, Quat, bern2};
use crate::error::{InputError, Result};
use crate::frames::geometry::{any_perpendicular, rotate_about};
use crate::run::alloc;
use crate::run::cancel::Cancel;

/// Simpson subintervals of the objective `Î(λ)` (MJ (41)).
pub const SIMPSON_N: usize = 20;

/// The fitted rational angle function of one segment.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AngleFit {
    /// Angle offset `φ` (rad) of `Ω̃ = φ + 2 sg arctan W`.
    pub phi: f64,
    /// `sg = sign k` (±1).
    pub sg: f64,
    /// End values `w₀, w₁` of `w = sg·tan((Ω − φ)/2)`.
    pub w: [f64; 2],
    /// End slopes `s₀, s₁` of `w` (per unit `v`).
    pub s: [f64; 2],
    pub lambda_star: f64,
    pub lambda: f64,
    pub beta: [f64; 3],
    pub gamma: [f64; 3],
    pub imin: f64,
}

impl AngleFit {
    /// `W(v)` and `W′(v)`.
    pub fn w_and_slope(&self, v: f64) -> (f64, f64) {
        let bb = bern2(v);
        let (g, b) = (self.gamma, self.beta);
        let num = g[0] * bb[0] + g[1] * bb[1] + g[2] * bb[2];
        let den = b[0] * bb[0] + b[1] * bb[1] + b[2] * bb[2];
        // derivative of the Bernstein quadratic: 2((c1 − c0)(1 − v) + (c2 − c1)v)
        let dn = 2.0 * ((g[1] - g[0]) * (1.0 - v) + (g[2] - g[1]) * v);
        let dd = 2.0 * ((b[1] - b[0]) * (1.0 - v) + (b[2] - b[1]) * v);
        (num / den, (dn * den - num * dd) / (den * den))
    }

    /// The approximate angle `Ω̃(v) = φ + 2 sg arctan W(v)`.
    pub fn angle(&self, v: f64) -> f64 {
        self.phi + 2.0 * self.sg * self.w_and_slope(v).0.atan()
    }
}

/// Frame data of one spline segment.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Segment {
    /// The cubic is a straight segment (the reference vector is carried unchanged).
    pub straight: bool,
    /// Reference vector at the start (carried unchanged along a straight segment).
    pub r: DVec3,
    /// RMF angle `Ω(0)` (rad, from `n` towards `b`) at the start.
    pub omega0: f64,
    /// RMF angle `Ω(1)` (rad) at the end.
    pub omega1: f64,
    /// The factor `k` of the cubic's [`super::Invariants`] (0 when planar).
    pub k: f64,
    /// `a` of the speed (see [`super::Invariants`]).
    pub a: f64,
    /// `b` of the speed (see [`super::Invariants`]).
    pub b: f64,
    /// `c` of the speed (see [`super::Invariants`]).
    pub c: f64,
    /// `σ/3` in Bernstein form: `(L₁, L₂cθ, L₃)`.
    pub speed: [f64; 3],
    /// Quaternion preimage `A₀, A₁` (scalar first).
    pub q: [Quat; 2],
    /// Angle of the principal normal from the Euler–Rodrigues `e₂` towards `e₃` (constant).
    pub beta: f64,
    pub fit: AngleFit,
}

/// Number of floats in [`Segment::to_row`].
pub const SEGMENT_ROW: usize = 34;

impl Segment {
    /// Exact angle `Ω(v) = Ω(0) + 2k[arctan((cv − b)/a) + arctan(b/a)]`, evaluated as
    /// `Ω(0) + 2k·atan2(a v, L₁ − b v)` (the same angle by the arctan addition theorem with
    /// `a² + b² = cL₁`; no `c`, which cancels on nearly straight cubics).
    pub fn omega(&self, v: f64) -> f64 {
        if self.k == 0.0 || self.straight {
            return self.omega0;
        }
        self.omega0 + 2.0 * self.k * (self.a * v).atan2(self.speed[0] - self.b * v)
    }

    /// `Ω̇(v) = −τσ = 2kca/(a² + (cv − b)²) = 2ka/(σ/3)`.
    pub fn omega_dot(&self, v: f64) -> f64 {
        if self.k == 0.0 || self.straight {
            return 0.0;
        }
        let w = bern2(v);
        let s3 = self.speed[0] * w[0] + self.speed[1] * w[1] + self.speed[2] * w[2];
        2.0 * self.k * self.a / s3
    }

    /// `[straight, Ω₀, Ω₁, k, a, b, c, φ, sg, λ, λ*, Î, β₀..₂, γ₀..₂, r, w₀, w₁, s₀, s₁, A₀, A₁,
    /// β_erf]` (the last: the angle of `n` from the Euler–Rodrigues `e₂`).
    pub fn to_row(&self) -> [f64; SEGMENT_ROW] {
        let f = &self.fit;
        [
            if self.straight { 1.0 } else { 0.0 },
            self.omega0,
            self.omega1,
            self.k,
            self.a,
            self.b,
            self.c,
            f.phi,
            f.sg,
            f.lambda,
            f.lambda_star,
            f.imin,
            f.beta[0],
            f.beta[1],
            f.beta[2],
            f.gamma[0],
            f.gamma[1],
            f.gamma[2],
            self.r.x,
            self.r.y,
            self.r.z,
            f.w[0],
            f.w[1],
            f.s[0],
            f.s[1],
            self.q[0][0],
            self.q[0][1],
            self.q[0][2],
            self.q[0][3],
            self.q[1][0],
            self.q[1][1],
            self.q[1][2],
            self.q[1][3],
            self.beta,
        ]
    }
}

/// Frenet frame `(n, b, t)` of a cubic at `v` (None where `ẋ × ẍ` vanishes).
pub fn frenet(c: &Cubic, v: f64) -> Option<(DVec3, DVec3, DVec3)> {
    let d1 = c.d1(v);
    let bh = d1.cross(c.d2(v));
    let (l1, lb) = (d1.length(), bh.length());
    if !(lb > 1e-14 * l1 * l1) {
        return None;
    }
    let t = d1 / l1;
    let b = bh / lb;
    Some((b.cross(t), b, t))
}

/// Frame data of one bent cubic without the angles (None for straight cubics, cubics with
/// a zero leg or a cusp).
fn bent(c: &Cubic) -> Option<Segment> {
    if c.is_straight() {
        return None;
    }
    let (a0, a1, _) = c.preimage()?;
    let (n, _, _) = frenet(c, 0.5)?;
    let (_, e2, e3) = super::erf(a0, a1, 0.5)?;
    let inv = c.invariants();
    Some(Segment {
        k: if inv.a > 0.0 && inv.c > 0.0 {
            inv.k
        } else {
            0.0
        },
        a: inv.a,
        b: inv.b,
        c: inv.c,
        speed: [inv.l[0], inv.l[1] * inv.ctheta, inv.l[2]],
        q: [a0, a1],
        beta: n.dot(e3).atan2(n.dot(e2)),
        ..Segment::default()
    })
}

/// Angle data of one non-straight cubic started at `Ω(0) = omega0`; `phi = None` is the
/// centred offset. None for straight cubics.
pub fn segment(c: &Cubic, omega0: f64, phi: Option<f64>) -> Option<Segment> {
    let mut seg = bent(c)?;
    seg.omega0 = omega0;
    seg.omega1 = seg.omega(1.0);
    seg.fit = fit_angle(&seg, phi);
    Some(seg)
}

/// The Frenet frame `(n, b, t)` of a bent segment at `v`, evaluated as the Euler–Rodrigues
/// frame of the preimage turned by the constant `β`: well conditioned also where `ẋ × ẍ`
/// is tiny (nearly straight cubics), and any error in `β` cancels in the RMF because the
/// start angle is measured in the same frame.
pub fn frenet_of(seg: &Segment, v: f64) -> Option<(DVec3, DVec3, DVec3)> {
    let (t, e2, e3) = super::erf(seg.q[0], seg.q[1], v)?;
    let (sb, cb) = seg.beta.sin_cos();
    Some((cb * e2 + sb * e3, cb * e3 - sb * e2, t))
}

fn simpson(f: impl Fn(f64) -> f64) -> f64 {
    let n = SIMPSON_N;
    let h = 1.0 / n as f64;
    let mut acc = f(0.0) + f(1.0);
    for j in 1..n {
        let w = if j % 2 == 1 { 4.0 } else { 2.0 };
        acc += w * f(j as f64 * h);
    }
    acc * h / 3.0
}

/// The rational Hermite interpolant for a given λ (MJ (36)–(37)).
fn coefficients(fit: &mut AngleFit, lambda: f64) {
    let ([w0, w1], [s0, s1]) = (fit.w, fit.s);
    let l2 = lambda + 2.0;
    let b2 = (w1 - w0) * l2 - s0;
    fit.lambda = lambda;
    fit.beta = [s1, s1 * l2 / 2.0, b2];
    fit.gamma = [w0 * s1, s1 * (w0 * l2 + s0) / 2.0, w1 * b2];
}

fn objective(seg: &Segment, fit: &AngleFit) -> f64 {
    simpson(|v| {
        let (w, dw) = fit.w_and_slope(v);
        let e = 2.0 * dw / (1.0 + w * w) - fit.sg * seg.omega_dot(v);
        e * e
    })
}

/// Fit of the rational angle function (our minimiser; MJ do not specify one): λ = λ* + e^μ,
/// scan μ ∈ [−12, 8] (201 points), golden section around the best scan point.
pub fn fit_angle(seg: &Segment, phi: Option<f64>) -> AngleFit {
    let d_omega = seg.omega1 - seg.omega0;
    if seg.k == 0.0 || d_omega.abs() < 1e-12 {
        // planar: the frame is the Frenet frame turned by a constant
        return AngleFit {
            phi: seg.omega0,
            sg: 1.0,
            beta: [1.0; 3],
            ..AngleFit::default()
        };
    }
    let sg = seg.k.signum();
    let phi = phi.unwrap_or((seg.omega0 + seg.omega1) / 2.0);
    let half = |v: f64| (seg.omega(v) - phi) / 2.0;
    let w = [sg * half(0.0).tan(), sg * half(1.0).tan()];
    let slope = |v: f64| sg * seg.omega_dot(v) / (2.0 * half(v).cos().powi(2));
    let mut fit = AngleFit {
        phi,
        sg,
        w,
        s: [slope(0.0), slope(1.0)],
        ..AngleFit::default()
    };
    fit.lambda_star = fit.s[0] / (w[1] - w[0]) - 2.0;
    let eval = |mu: f64| {
        let mut f = fit;
        coefficients(&mut f, fit.lambda_star + mu.exp());
        objective(seg, &f)
    };
    let (lo, hi, n): (f64, f64, usize) = (-12.0, 8.0, 201);
    let step = (hi - lo) / (n - 1) as f64;
    let mut best = (0usize, f64::INFINITY);
    for i in 0..n {
        let val = eval(lo + i as f64 * step);
        if val < best.1 {
            best = (i, val);
        }
    }
    let mut a = lo + best.0.saturating_sub(1) as f64 * step;
    let mut b = lo + (best.0 + 1).min(n - 1) as f64 * step;
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let mut x1 = b - g * (b - a);
    let mut x2 = a + g * (b - a);
    let (mut f1, mut f2) = (eval(x1), eval(x2));
    while b - a > 1e-10 {
        if f1 <= f2 {
            b = x2;
            x2 = x1;
            f2 = f1;
            x1 = b - g * (b - a);
            f1 = eval(x1);
        } else {
            a = x1;
            x1 = x2;
            f1 = f2;
            x2 = a + g * (b - a);
            f2 = eval(x2);
        }
    }
    let mu = (a + b) / 2.0;
    let lambda = fit.lambda_star + mu.exp();
    coefficients(&mut fit, lambda);
    fit.imin = objective(seg, &fit);
    fit
}

/// How the start of the spline's RMF is given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Start {
    /// A reference vector, projected onto the normal plane at the start.
    Vector(DVec3),
    /// The angle from the principal normal towards the binormal of the first bent segment.
    Angle(f64),
}

/// Segments between polls of the sequential pass of [`setup`].
const CHAIN_BLOCK: usize = 1 << 10;
/// Segments per block of the parallel angle fits (each about 30 µs).
const FIT_GRAIN: usize = 16;

/// Frame data of every segment of a G¹ PH spline.
/// `omega_start` and `phi`, when given, must be finite.
///
/// Polls `cancel` and fails with [`InputError::stopped`] once it says stop. The reference vector is
/// carried from segment to segment in one sequential pass; the rational angle fits ([`fit_angle`],
/// which depend only on their own segment) follow in parallel, so the result is that of fitting
/// each segment in the pass.
pub fn setup(
    cubics: &[Cubic],
    start: Start,
    phi: Option<f64>,
    cancel: Cancel<'_>,
) -> Result<Vec<Segment>> {
    if let Start::Angle(om) = start {
        if !om.is_finite() {
            return Err(InputError::new("omega_start", "must be finite"));
        }
    }
    if phi.is_some_and(|p| !p.is_finite()) {
        return Err(InputError::new("phi", "must be finite"));
    }
    let Some(first) = cubics.first() else {
        return Ok(Vec::new());
    };
    let t0 = first.d1(0.0).normalize();
    let mut r = match start {
        Start::Vector(v) => {
            let p = v - v.dot(t0) * t0;
            if !(p.length() > 1e-9 * v.length()) || !p.is_finite() {
                return Err(InputError::new(
                    "initial",
                    "is zero, not finite or parallel to the tangent at the start",
                ));
            }
            p.normalize()
        }
        Start::Angle(om) => match cubics
            .iter()
            .find_map(|c| bent(c).and_then(|s| frenet_of(&s, 0.0)))
        {
            Some((n, b, _)) => om.sin() * b + om.cos() * n,
            None => {
                let p = any_perpendicular(t0);
                rotate_about(p, t0, om)
            }
        },
    };
    let mut out = alloc::with_capacity("PHSpline frames", cubics.len())?;
    for (i, c) in cubics.iter().enumerate() {
        if i % CHAIN_BLOCK == 0 && cancel() {
            return Err(InputError::stopped());
        }
        let found =
            bent(c).and_then(|seg| Some((frenet_of(&seg, 0.0)?, frenet_of(&seg, 1.0)?, seg)));
        match found {
            None => {
                let t = c.d1(0.0).normalize();
                let p = r - r.dot(t) * t;
                if !(p.length() > 1e-6) {
                    return Err(InputError::new(
                        "control_points",
                        format!("segment {i}: the reference vector is parallel to the tangent"),
                    ));
                }
                r = p.normalize();
                out.push(Segment {
                    straight: true,
                    r,
                    fit: AngleFit {
                        sg: 1.0,
                        beta: [1.0; 3],
                        ..AngleFit::default()
                    },
                    ..Segment::default()
                });
            }
            Some(((n0, b0, _), (n1, b1, _), mut seg)) => {
                seg.omega0 = r.dot(b0).atan2(r.dot(n0));
                seg.omega1 = seg.omega(1.0);
                seg.r = r; // fallback should the frame be undefined somewhere (a cusp)
                r = seg.omega1.sin() * b1 + seg.omega1.cos() * n1;
                out.push(seg);
            }
        }
    }
    let fit = |i: usize| {
        let seg = &out[i];
        if seg.straight {
            seg.fit
        } else {
            fit_angle(seg, phi)
        }
    };
    let Some(fits) = alloc::rows("PHSpline frames", out.len(), FIT_GRAIN, cancel, fit)? else {
        return Err(InputError::stopped());
    };
    for (seg, fit) in out.iter_mut().zip(fits) {
        seg.fit = fit;
    }
    Ok(out)
}

/// Frame mode for [`frame_at`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    Frenet,
    Exact,
    Rational,
}

/// The frame (columns `r, s, t`) and its angle from `n` at `v` of a segment. On straight
/// segments (no Frenet frame) every mode carries the reference vector; the angle is 0.
/// (A bent PH cubic has κ > 0 on [0, 1]; should `ẋ × ẍ` still underflow, the start vector
/// projected onto the normal plane stands in, never a NaN.)
pub fn frame_at(c: &Cubic, seg: &Segment, v: f64, mode: Mode) -> (DMat3, f64) {
    let fr = if seg.straight {
        None
    } else {
        frenet_of(seg, v)
    };
    match fr {
        None => {
            let t = c.d1(v).normalize_or(DVec3::Z);
            let r = (seg.r - seg.r.dot(t) * t)
                .try_normalize()
                .unwrap_or_else(|| any_perpendicular(t));
            (DMat3::from_cols(r, t.cross(r), t), 0.0)
        }
        Some((n, b, t)) => {
            let om = match mode {
                Mode::Frenet => 0.0,
                Mode::Exact => seg.omega(v),
                Mode::Rational => seg.fit.angle(v),
            };
            let (so, co) = om.sin_cos();
            let r = so * b + co * n;
            let s = co * b - so * n;
            (DMat3::from_cols(r, s, t), om)
        }
    }
}

/// Rows of a block of [`frames_at`] between polls.
const CANCEL_ROWS: usize = 1 << 16;

/// Frames (row-major, columns `r, s, t`, as NumPy sees an `(n, 3, 3)` array) and their
/// angles from the principal normal at the global parameters `s` of a G¹ PH spline (see
/// [`super::locate`]), in parallel: [`setup`] once, then [`frame_at`] per parameter.
/// `frames` and `angles` hold one entry per parameter.
///
/// Polls `cancel` before every block of [`CANCEL_ROWS`] rows and skips the remaining blocks once it
/// says stop (the outputs are then incomplete; see [`crate::run::cancel`]).
#[allow(clippy::too_many_arguments)]
pub fn frames_at(
    cubics: &[Cubic],
    s: &[f64],
    start: Start,
    phi: Option<f64>,
    mode: Mode,
    frames: &mut [[f64; 9]],
    angles: &mut [f64],
    cancel: crate::run::cancel::Cancel<'_>,
) -> Result<()> {
    use rayon::prelude::*;
    debug_assert!(frames.len() == s.len() && angles.len() == s.len());
    super::check_params(cubics.len(), s, cancel)?;
    let segs = setup(cubics, start, phi, cancel)?;
    frames
        .par_chunks_mut(CANCEL_ROWS)
        .zip(angles.par_chunks_mut(CANCEL_ROWS))
        .zip(s.par_chunks(CANCEL_ROWS))
        .for_each(|((fb, ab), sb)| {
            if cancel() {
                return;
            }
            fb.par_iter_mut()
                .zip(ab.par_iter_mut())
                .zip(sb.par_iter())
                .for_each(|((f, a), &x)| {
                    let (i, v) = super::locate(cubics.len(), x);
                    let (m, om) = frame_at(&cubics[i], &segs[i], v, mode);
                    // glam is column-major; the NumPy frame is row-major with columns r, s, t
                    *f = m.transpose().to_cols_array();
                    *a = om;
                });
        });
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::cancel;

    fn r1() -> Cubic {
        Cubic::new([
            DVec3::X,
            DVec3::new(1.0, 0.5858183513, 0.2929091757),
            DVec3::new(0.5858183513, 1.0, 0.4924889878),
            DVec3::new(0.0, 1.0, std::f64::consts::FRAC_PI_4),
        ])
    }

    #[test]
    fn r1_fit_reference() {
        let seg = segment(&r1(), std::f64::consts::FRAC_PI_2, None).unwrap();
        assert!((seg.omega1 - 0.8414599690).abs() < 1e-8, "{}", seg.omega1);
        assert!(
            (seg.fit.imin - 6.686905e-07).abs() < 1e-11,
            "{}",
            seg.fit.imin
        );
        assert!((seg.fit.lambda - -0.1625470092).abs() < 1e-6);
    }

    #[test]
    fn frames_at_agrees_with_frame_at_per_segment() {
        let c = [
            r1(),
            Cubic::new([
                r1().b[3],
                r1().b[3] + DVec3::Z,
                r1().b[3] + 2.0 * DVec3::Z,
                r1().b[3] + 3.0 * DVec3::Z,
            ]),
        ];
        let s = [0.0, 0.3, 1.0, 1.7, 2.0];
        let start = Start::Angle(0.4);
        let segs = setup(&c, start, None, &cancel::never).unwrap();
        for mode in [Mode::Frenet, Mode::Exact, Mode::Rational] {
            let mut f = vec![[0.0; 9]; s.len()];
            let mut a = vec![0.0; s.len()];
            frames_at(&c, &s, start, None, mode, &mut f, &mut a, &cancel::never).unwrap();
            for (k, &x) in s.iter().enumerate() {
                let (i, v) = crate::ph::locate(c.len(), x);
                let (m, om) = frame_at(&c[i], &segs[i], v, mode);
                assert_eq!(f[k], m.transpose().to_cols_array());
                assert_eq!(a[k], om);
            }
        }
        let mut f = vec![[0.0; 9]; 1];
        let e = frames_at(
            &c,
            &[-0.5],
            start,
            None,
            Mode::Exact,
            &mut f,
            &mut [0.0],
            &cancel::never,
        )
        .unwrap_err();
        assert_eq!(e.arg, "s");
    }

    #[test]
    fn setup_needs_a_finite_start_angle_and_offset() {
        let c = [r1()];
        let e = setup(&c, Start::Angle(f64::NAN), None, &cancel::never).unwrap_err();
        assert_eq!(e.to_string(), "omega_start: must be finite");
        let e = setup(&c, Start::Angle(0.0), Some(f64::INFINITY), &cancel::never).unwrap_err();
        assert_eq!(e.to_string(), "phi: must be finite");
        let e = setup(
            &c,
            Start::Vector(DVec3::new(f64::NAN, 0.0, 1.0)),
            None,
            &cancel::never,
        )
        .unwrap_err();
        assert_eq!(e.arg, "initial");
        assert!(setup(&c, Start::Angle(0.3), Some(0.1), &cancel::never).is_ok());
    }
}
