//! G¹ Hermite interpolation by PH cubics (Mäurer & Jüttler 1999, §3.2, Table 1). Table 1's
//! equation (*) is printed with `(|λ₁| − X)(|λ₂| − X)`, right only when `λ₁ ≥ 0 ≥ λ₂`; the
//! leg lengths are `L₁ = λ₁ − X`, `L₃ = −λ₂ − X`, so we solve the signed equation below and
//! keep the roots with `L₁, L₃ > 0` (correct orientation).
//!
//! Given end points `p₀, p₁` and unit tangents `t₀, t₁`, with `C = t₀·t₁`, `D = p₁ − p₀`,
//! `s² = 1 − C²`, the feet of the common perpendicular of the tangent lines are
//! `n₁ = p₀ + λ₁t₀`, `n₂ = p₁ + λ₂t₁` with `λ₁ = (t₀·D − C t₁·D)/s²`,
//! `λ₂ = −(t₁·D − C t₀·D)/s²`. The inner control points are `b₁ = n₁ − X t₀`,
//! `b₂ = n₂ + X t₁` where `X` solves
//!
//! ```text
//! (λ₁ − X)(−λ₂ − X) − 2(1 + C)X² = R,   R = 2|n₁ − n₂|²/(1 − C)
//! ```
//!
//! and only roots with `L₁ = λ₁ − X > 0` and `L₃ = −λ₂ − X > 0` give a forward polygon.
//!
//! Evaluated as printed, `λ₁, λ₂ ~ h/s²` cancel catastrophically for nearly parallel
//! tangents (fine segments of gently curved data) and for nearly antiparallel ones. We solve
//! the same equation for the mean leg `M = (L₁ + L₃)/2` instead, with the orthogonal pair
//! `t_m = t₀ + t₁ = a m̂`, `t_d = t₀ − t₁ = b û` (`a² + b² = 4`):
//!
//! ```text
//! L₁ − L₃ = λ₁ + λ₂ = 2(û·D)/b,   X = (λ₁ − λ₂)/2 − M = (m̂·D)/a − M,
//! (1 − a²)M² + 2a(m̂·D)M − (m̂·D)² − [(û·D)² + 4(D·(û × m̂))²]/b² = 0
//! ```
//!
//! (`1 − a² = −(1 + 2C)`: linear at `C = −1/2`), `b₁ = p₀ + L₁t₀`, `b₂ = p₁ − L₃t₁`. Every
//! term stays bounded as `b → 0` for data from a smooth curve, and as `a → 0` the equation
//! becomes the planar closed form `M = √(d² + 4e²)/2` of antiparallel tangents
//! (`d = D·t₀`, `e = |D − d t₀|`), so no separate branch is needed there (the end tangents
//! stay exact). Exactly parallel tangents (`|t₀ − t₁| < 1e-8`) are interpolated only by the
//! straight line, when the chord is along them.

use glam::DVec3;

use super::Cubic;
use crate::error::{InputError, Result};
use crate::frames::geometry::any_perpendicular;
use crate::run::alloc;
use crate::run::cancel::{self, Cancel};

/// `|t₀ − t₁|` below which tangents count as parallel (angle < 1e-8 rad).
pub const EPS_PARALLEL: f64 = 1e-8;
/// `1 + C` below which data with `p₁` on the tangent line of `p₀` are refused.
pub const EPS_ANTI: f64 = 1e-11;
/// `|1 + 2C|` below which the equation is treated as linear.
pub const EPS_LINEAR: f64 = 1e-12;

/// Why there is no interpolating PH cubic.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NoSolution {
    /// `t₀ = t₁` and the chord is not along them.
    Parallel,
    /// `t₀ = −t₁` and `p₁` lies on the tangent line of `p₀`.
    AntiparallelOnLine,
    /// Negative discriminant (S-shaped data, an inflection inside, too long a segment).
    NoRealRoot,
    /// The real roots all give a reversed control polygon.
    Reversed,
}

impl NoSolution {
    pub fn message(self) -> &'static str {
        match self {
            NoSolution::Parallel => {
                "no PH cubic: end tangents are parallel (t0·t1 = 1) but the chord is not \
                 along them; split the segment"
            }
            NoSolution::AntiparallelOnLine => {
                "no PH cubic: end tangents are antiparallel (t0·t1 = -1) and p1 lies on the \
                 tangent line of p0"
            }
            NoSolution::NoRealRoot => {
                "no PH cubic interpolates these data (negative discriminant): S-shaped data / \
                 an inflection inside the segment / segment too long; split it"
            }
            NoSolution::Reversed => {
                "no PH cubic interpolates these data (only reversed control polygons): \
                 S-shaped data / an inflection inside the segment / segment too long; split it"
            }
        }
    }

    /// Small integer code (for the binding).
    pub fn code(self) -> i64 {
        match self {
            NoSolution::Parallel => 1,
            NoSolution::AntiparallelOnLine => 2,
            NoSolution::NoRealRoot => 3,
            NoSolution::Reversed => 4,
        }
    }
}

/// The interpolants, shortest control polygon first (0, 1 or 2 of them); `reason` says
/// why there are none.
#[derive(Debug, Clone, PartialEq)]
pub struct Solutions {
    pub cubics: Vec<Cubic>,
    pub reason: Option<NoSolution>,
}

fn polygon(c: &Cubic) -> f64 {
    c.legs().iter().map(|d| d.length()).sum()
}

/// G¹ Hermite interpolation. `t0`, `t1` must be unit vectors, `p0 ≠ p1`, all finite (the
/// caller checks).
pub fn hermite(p0: DVec3, t0: DVec3, p1: DVec3, t1: DVec3) -> Solutions {
    let none = |r| Solutions {
        cubics: Vec::new(),
        reason: Some(r),
    };
    let one = |c| Solutions {
        cubics: vec![c],
        reason: None,
    };
    let c = t0.dot(t1);
    let d = p1 - p0;
    let dl = d.length();
    // symmetric and antisymmetric tangents: tm ⟂ td, |tm|² + |td|² = 4
    let (tm, td) = (t0 + t1, t0 - t1);
    let (a, b) = (tm.length(), td.length());
    if c > 0.0 && b < EPS_PARALLEL {
        let along = d.dot(t0);
        if d.cross(t0).length() <= 1e-8 * dl && along > 0.0 {
            return one(Cubic::new([p0, p0 + d / 3.0, p0 + 2.0 * d / 3.0, p1]));
        }
        return none(NoSolution::Parallel);
    }
    let u = td / b;
    if c < 0.0 && 1.0 + c < EPS_ANTI {
        let e = (d - d.dot(t0) * t0).length();
        if !(e > 1e-14 * dl) {
            return none(NoSolution::AntiparallelOnLine);
        }
    }
    // m̂: unit along tm, made exactly ⟂ û (any perpendicular when tm vanishes)
    let m = {
        let p = tm - tm.dot(u) * u;
        if a > 1e-12 {
            p.normalize()
        } else {
            any_perpendicular(u)
        }
    };
    let md = m.dot(d);
    let ud = u.dot(d);
    let wd = d.dot(u.cross(m));
    let delta = 2.0 * ud / b; // L₁ − L₃ = λ₁ + λ₂
    let qa = 1.0 - a * a; // = −(1 + 2C)
    let qb = 2.0 * a * md;
    let qc = -(md * md) - (ud * ud + 4.0 * wd * wd) / (b * b);
    // at most two roots (and cubics below): sizes bounded by a constant
    let mut roots: Vec<f64> = Vec::with_capacity(2);
    if qa.abs() < EPS_LINEAR {
        if qb != 0.0 {
            roots.push(-qc / qb);
        }
    } else {
        let disc = qb * qb - 4.0 * qa * qc;
        if disc < 0.0 {
            return none(NoSolution::NoRealRoot);
        }
        let sq = disc.sqrt();
        let q = -(qb + if qb >= 0.0 { sq } else { -sq }) / 2.0;
        if q != 0.0 {
            roots.push(q / qa);
            if disc > 0.0 {
                roots.push(qc / q);
            }
        } else {
            roots.push(0.0);
        }
    }
    let mut cubics: Vec<Cubic> = roots
        .into_iter()
        .filter(|&mm| mm.is_finite() && mm + delta / 2.0 > 0.0 && mm - delta / 2.0 > 0.0)
        .map(|mm| {
            let (l1, l3) = (mm + delta / 2.0, mm - delta / 2.0);
            Cubic::new([p0, p0 + l1 * t0, p1 - l3 * t1, p1])
        })
        .collect();
    if cubics.is_empty() {
        return none(if qa.abs() < EPS_LINEAR && qb == 0.0 {
            NoSolution::NoRealRoot
        } else {
            NoSolution::Reversed
        });
    }
    cubics.sort_by(|a, b| polygon(a).total_cmp(&polygon(b)));
    Solutions {
        cubics,
        reason: None,
    }
}

/// Floats per row of [`Rows::candidates`]: two cubics of four control points.
pub const CANDIDATE_ROW: usize = 24;

/// [`hermite`] on many data sets (one per row), packed for NumPy.
#[derive(Debug, Clone, PartialEq)]
pub struct Rows {
    /// `m × 24` floats: row `i` holds the control points of its 0, 1 or 2 cubics
    /// (shortest polygon first), zeros after them.
    pub candidates: Vec<f64>,
    /// Number of cubics of each row.
    pub counts: Vec<i64>,
    /// [`NoSolution::code`] of each row without a cubic, 0 elsewhere.
    pub codes: Vec<i64>,
}

/// G¹ Hermite interpolation of rows `(p0[i], t0[i], p1[i], t1[i])`; the tangents need not be
/// unit (they are normalised). Every row is checked (finite, non-zero tangents, `p₀ ≠ p₁`);
/// with `all = false` the first row without a solution is an error, otherwise its reason
/// is recorded in [`Rows::codes`]. With `batch` the messages name the row.
///
/// Polls `cancel` every [`cancel::BLOCK`] rows and fails with [`InputError::stopped`] once it says
/// stop.
#[allow(clippy::too_many_arguments)]
pub fn hermite_rows(
    p0: &[DVec3],
    t0: &[DVec3],
    p1: &[DVec3],
    t1: &[DVec3],
    all: bool,
    batch: bool,
    cancel: Cancel<'_>,
) -> Result<Rows> {
    let m = p0.len();
    if t0.len() != m || p1.len() != m || t1.len() != m {
        return Err(InputError::new(
            "p0, t0, p1, t1",
            "must have the same number of rows",
        ));
    }
    // reserved, then written row by row: the pages are touched between the polls, not
    // all at once before the first
    let mut out = Rows {
        candidates: alloc::with_capacity(
            "ph.hermite",
            alloc::product("ph.hermite", m, CANDIDATE_ROW, 8)?,
        )?,
        counts: alloc::with_capacity("ph.hermite", m)?,
        codes: alloc::with_capacity("ph.hermite", m)?,
    };
    for i in 0..m {
        if i % cancel::BLOCK == 0 && cancel() {
            return Err(InputError::stopped());
        }
        let at = |arg: &'static str, msg: &str| {
            let msg = if batch {
                format!("row {i}: {msg}")
            } else {
                msg.to_string()
            };
            InputError::new(arg, msg)
        };
        for (arg, v) in [("p0", p0[i]), ("t0", t0[i]), ("p1", p1[i]), ("t1", t1[i])] {
            if !v.is_finite() {
                return Err(at(arg, "contains non-finite values"));
            }
        }
        for (arg, v) in [("t0", t0[i]), ("t1", t1[i])] {
            if !(v.length() > 0.0) {
                return Err(at(arg, "zero tangent vector"));
            }
        }
        if p0[i] == p1[i] {
            return Err(at("p1", "equals p0 (no segment to interpolate)"));
        }
        let sol = hermite(p0[i], t0[i].normalize(), p1[i], t1[i].normalize());
        if let Some(r) = sol.reason {
            if !all {
                return Err(at("p0, t0, p1, t1", r.message()));
            }
        }
        out.codes.push(sol.reason.map_or(0, |r| r.code()));
        out.counts.push(sol.cubics.len() as i64);
        let mut row = [0.0; CANDIDATE_ROW];
        for (j, c) in sol.cubics.iter().enumerate() {
            let f: &[f64] = bytemuck::cast_slice(&c.b);
            row[j * 12..j * 12 + 12].copy_from_slice(f);
        }
        out.candidates.extend_from_slice(&row);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn helix_quarter_turn_r1() {
        let s = 1.25f64.sqrt();
        let sol = hermite(
            DVec3::X,
            DVec3::new(0.0, 1.0, 0.5) / s,
            DVec3::new(0.0, 1.0, std::f64::consts::FRAC_PI_4),
            DVec3::new(-1.0, 0.0, 0.5) / s,
        );
        assert_eq!(sol.cubics.len(), 2);
        let b1 = sol.cubics[0].b[1];
        assert!((b1 - DVec3::new(1.0, 0.5858183513, 0.2929091757)).length() < 1e-9);
        assert!(sol.cubics[0].is_ph(1e-9) && sol.cubics[1].is_ph(1e-9));
    }

    /// Table 1's λ form (with the signed equation), as a reference for the M form.
    fn lambda_form(p0: DVec3, t0: DVec3, p1: DVec3, t1: DVec3) -> Vec<[DVec3; 2]> {
        let (c, d) = (t0.dot(t1), p1 - p0);
        let s2 = t0.cross(t1).length_squared();
        let lam1 = (t0.dot(d) - c * t1.dot(d)) / s2;
        let lam2 = -(t1.dot(d) - c * t0.dot(d)) / s2;
        let (n1, n2) = (p0 + lam1 * t0, p1 + lam2 * t1);
        let r = 2.0 * (n1 - n2).length_squared() / (1.0 - c);
        let (qa, qb, qc) = (1.0 + 2.0 * c, lam1 - lam2, lam1 * lam2 + r);
        let disc = qb * qb - 4.0 * qa * qc;
        if disc < 0.0 {
            return Vec::new();
        }
        [
            (-qb + disc.sqrt()) / (2.0 * qa),
            (-qb - disc.sqrt()) / (2.0 * qa),
        ]
        .into_iter()
        .filter(|&x| lam1 - x > 0.0 && -lam2 - x > 0.0)
        .map(|x| [n1 - x * t0, n2 + x * t1])
        .collect()
    }

    #[test]
    fn mean_leg_form_equals_the_printed_lambda_form() {
        // a small deterministic generator (no rand dependency)
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let mut compared = 0;
        for _ in 0..5000 {
            let mut v = || DVec3::new(next(), next(), next());
            let (p0, t0, p1, t1) = (v(), v().normalize(), v(), v().normalize());
            let c = t0.dot(t1);
            if (1.0 + 2.0 * c).abs() < 1e-3 || 1.0 - c.abs() < 1e-3 {
                continue;
            }
            let mut want = lambda_form(p0, t0, p1, t1);
            let got = hermite(p0, t0, p1, t1).cubics;
            assert_eq!(got.len(), want.len());
            want.sort_by(|a, b| {
                let la = (a[0] - p0).length() + (a[1] - a[0]).length() + (p1 - a[1]).length();
                let lb = (b[0] - p0).length() + (b[1] - b[0]).length() + (p1 - b[1]).length();
                la.total_cmp(&lb)
            });
            for (g, w) in got.iter().zip(&want) {
                let scale = 1.0 + g.b[1].length() + g.b[2].length();
                assert!((g.b[1] - w[0]).length() < 1e-8 * scale, "{:?} {:?}", g.b, w);
                assert!((g.b[2] - w[1]).length() < 1e-8 * scale);
                compared += 1;
            }
        }
        assert!(compared > 1500, "{compared}");
    }

    #[test]
    fn parallel_not_straight_has_no_solution() {
        let sol = hermite(DVec3::ZERO, DVec3::Y, DVec3::X, DVec3::Y);
        assert_eq!(sol.reason, Some(NoSolution::Parallel));
    }

    #[test]
    fn hermite_rows_packs_each_row_and_names_bad_rows() {
        let s = 1.25f64.sqrt();
        let (p0, t0) = (DVec3::X, DVec3::new(0.0, 1.0, 0.5) / s);
        let (p1, t1) = (
            DVec3::new(0.0, 1.0, std::f64::consts::FRAC_PI_4),
            DVec3::new(-1.0, 0.0, 0.5) / s,
        );
        // row 0: the helix quarter turn with unnormalised tangents; row 1: parallel, no cubic
        let rows = hermite_rows(
            &[p0, DVec3::ZERO],
            &[2.0 * t0, DVec3::Y],
            &[p1, DVec3::X],
            &[3.0 * t1, DVec3::Y],
            true,
            true,
            &cancel::never,
        )
        .unwrap();
        let want = hermite(p0, (2.0 * t0).normalize(), p1, (3.0 * t1).normalize());
        assert_eq!(rows.counts, vec![2, 0]);
        assert_eq!(rows.codes, vec![0, NoSolution::Parallel.code()]);
        assert_eq!(rows.candidates.len(), 2 * CANDIDATE_ROW);
        for (j, c) in want.cubics.iter().enumerate() {
            for (k, b) in c.b.iter().enumerate() {
                let o = j * 12 + 3 * k;
                assert_eq!(rows.candidates[o..o + 3], b.to_array());
            }
        }
        assert!(rows.candidates[CANDIDATE_ROW..].iter().all(|&x| x == 0.0));
        // all = false: the row without a cubic is an error naming it
        let e = hermite_rows(
            &[DVec3::ZERO],
            &[DVec3::Y],
            &[DVec3::X],
            &[DVec3::Y],
            false,
            true,
            &cancel::never,
        )
        .unwrap_err();
        assert_eq!(e.arg, "p0, t0, p1, t1");
        assert!(e.msg.starts_with("row 0: no PH cubic"), "{}", e.msg);
        let e = hermite_rows(
            &[DVec3::X],
            &[DVec3::ZERO],
            &[DVec3::Y],
            &[DVec3::Y],
            true,
            false,
            &cancel::never,
        )
        .unwrap_err();
        assert_eq!((&*e.arg, e.msg.as_str()), ("t0", "zero tangent vector"));
        let e = hermite_rows(
            &[DVec3::X],
            &[],
            &[DVec3::Y],
            &[DVec3::Y],
            true,
            false,
            &cancel::never,
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "p0, t0, p1, t1: must have the same number of rows"
        );
    }
}
