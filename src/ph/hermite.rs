//! G¹ Hermite interpolation by PH cubics (MJ §3.1, Table 1, with the corrected signed
//! equation of erratum PH-1).
//!
//! Given end points `p₀, p₁` and unit tangents `t₀, t₁`, with `C = t₀·t₁`, `D = p₁ − p₀`,
//! `s² = 1 − C²`, the feet of the common perpendicular of the tangent lines are
//! `n₁ = p₀ + λ₁t₀`, `n₂ = p₁ + λ₂t₁` with `λ₁ = (t₀·D − C t₁·D)/s²`,
//! `λ₂ = −(t₁·D − C t₀·D)/s²`. The inner control points are `b₁ = n₁ − X t₀`,
//! `b₂ = n₂ + X t₁` where `X` solves
//!
//! ```text
//! (λ₁ − X)(−λ₂ − X) − 2(1 + C)X² = R,   R = 2|n₁ − n₂|²/(1 − C)
//! ⇔ (1 + 2C)X² + (λ₁ − λ₂)X + λ₁λ₂ + R = 0
//! ```
//!
//! and only roots with `L₁ = λ₁ − X > 0` and `L₃ = −λ₂ − X > 0` give a forward polygon.
//! Special cases: `C = −1/2` (linear equation), `C ≈ 1` (only a straight line, when the
//! chord is along the tangents), `C ≈ −1` (planar closed form
//! `L₁ = (d + √(d² + 4e²))/2`, `L₃ = L₁ − d` with `d = D·t₀`, `e = |D − d t₀|`).

use glam::DVec3;

use super::Cubic;

/// `1 − C²` below which tangents with `C > 0` count as parallel.
pub const EPS_PARALLEL: f64 = 1e-10;
/// `1 + C` below which the antiparallel closed form is used.
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
    let s2 = t0.cross(t1).length_squared();
    let dl = d.length();
    if c > 0.0 && s2 < EPS_PARALLEL {
        let along = d.dot(t0);
        if d.cross(t0).length() <= 1e-8 * dl && along > 0.0 {
            return one(Cubic::new([p0, p0 + d / 3.0, p0 + 2.0 * d / 3.0, p1]));
        }
        return none(NoSolution::Parallel);
    }
    if c < 0.0 && 1.0 + c < EPS_ANTI {
        let dd = d.dot(t0);
        let e = (d - dd * t0).length();
        if !(e > 1e-14 * dl) {
            return none(NoSolution::AntiparallelOnLine);
        }
        let l1 = (dd + (dd * dd + 4.0 * e * e).sqrt()) / 2.0;
        let l3 = l1 - dd;
        return one(Cubic::new([p0, p0 + l1 * t0, p1 + l3 * t0, p1]));
    }
    let lam1 = (t0.dot(d) - c * t1.dot(d)) / s2;
    let lam2 = -(t1.dot(d) - c * t0.dot(d)) / s2;
    let n1 = p0 + lam1 * t0;
    let n2 = p1 + lam2 * t1;
    let r = 2.0 * (n1 - n2).length_squared() / (1.0 - c);
    let qa = 1.0 + 2.0 * c;
    let qb = lam1 - lam2;
    let qc = lam1 * lam2 + r;
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
        .filter(|&x| x.is_finite() && lam1 - x > 0.0 && -lam2 - x > 0.0)
        .map(|x| Cubic::new([p0, n1 - x * t0, n2 + x * t1, p1]))
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

    #[test]
    fn parallel_not_straight_has_no_solution() {
        let sol = hermite(DVec3::ZERO, DVec3::Y, DVec3::X, DVec3::Y);
        assert_eq!(sol.reason, Some(NoSolution::Parallel));
    }
}
