//! The cubic segment on a local parameter `λ ∈ [0, 1]`, in the three forms the crate uses
//! (Farin, "Curves and Surfaces for CAGD", 5th ed., §6.1 Bernstein/Bézier and de Casteljau,
//! §7.2 cubic Hermite interpolation):
//!
//! * **Hermite data** `(p₀, p₁, d₀, d₁)`: end values and end derivatives `dγ/dλ`.
//!   `γ(λ) = p₀ φ₀ + p₁ φ₁ + d₀ ψ₀ + d₁ ψ₁` with `φ₀ = 2λ³ − 3λ² + 1`, `φ₁ = −2λ³ + 3λ²`,
//!   `ψ₀ = λ³ − 2λ² + λ`, `ψ₁ = λ³ − λ²` ([`basis`]). Since `φ₁′ = −φ₀′` the derivative is
//!   evaluated as `(p₀ − p₁) φ₀′ + d₀ ψ₀′ + d₁ ψ₁′` ([`Hermite::slope`]).
//! * **Power form** `γ(λ) = a + bλ + cλ² + dλ³` with `a = p₀`, `b = d₀`,
//!   `c = 3(p₁ − p₀) − 2d₀ − d₁`, `d = 2(p₀ − p₁) + d₀ + d₁`, evaluated by Horner's rule
//!   ([`Power`]; the fastest for many evaluations of one segment).
//! * **Bézier form** `γ(λ) = Σ bᵢ Bᵢ³(λ)` with `b₀ = p₀`, `b₁ = p₀ + d₀/3`, `b₂ = p₁ − d₁/3`,
//!   `b₃ = p₁` (so `d₀ = 3(b₁ − b₀)`, `d₁ = 3(b₃ − b₂)`); the point by de Casteljau, the
//!   derivatives from the legs `dᵢ = bᵢ − bᵢ₋₁`: `γ′ = 3 Σ dᵢ Bᵢ²`,
//!   `γ″ = 6((d₂ − d₁)(1 − λ) + (d₃ − d₂)λ)`, `γ‴ = 6(d₃ − 2d₂ + d₁)` ([`Bezier`]).

use glam::DVec3;

/// Cubic Hermite basis `[φ₀, φ₁, ψ₀, ψ₁]` at `x` and its derivative `[φ₀′, φ₁′, ψ₀′, ψ₁′]`.
#[inline]
pub fn basis(x: f64) -> ([f64; 4], [f64; 4]) {
    let x2 = x * x;
    let x3 = x2 * x;
    (
        [
            2.0 * x3 - 3.0 * x2 + 1.0,
            -2.0 * x3 + 3.0 * x2,
            x3 - 2.0 * x2 + x,
            x3 - x2,
        ],
        [
            6.0 * x2 - 6.0 * x,
            -6.0 * x2 + 6.0 * x,
            3.0 * x2 - 4.0 * x + 1.0,
            3.0 * x2 - 2.0 * x,
        ],
    )
}

/// Bernstein basis of degree 2 at `v`: `[(1 − v)², 2(1 − v)v, v²]`.
#[inline]
pub fn bern2(v: f64) -> [f64; 3] {
    let u = 1.0 - v;
    [u * u, 2.0 * u * v, v * v]
}

/// Hermite data of one segment: end values and end derivatives with respect to `λ`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hermite {
    pub p0: DVec3,
    pub p1: DVec3,
    pub d0: DVec3,
    pub d1: DVec3,
}

impl Hermite {
    #[inline]
    pub fn new(p0: DVec3, p1: DVec3, d0: DVec3, d1: DVec3) -> Self {
        Hermite { p0, p1, d0, d1 }
    }

    /// `γ(λ)` in the basis form.
    #[inline]
    pub fn value(&self, l: f64) -> DVec3 {
        let (h, _) = basis(l);
        self.p0 * h[0] + self.d0 * h[2] + self.p1 * h[1] + self.d1 * h[3]
    }

    /// `dγ/dλ` in the basis form, `(p₀ − p₁) φ₀′ + d₀ ψ₀′ + d₁ ψ₁′`.
    #[inline]
    pub fn slope(&self, l: f64) -> DVec3 {
        let (_, h) = basis(l);
        (self.p0 - self.p1) * h[0] + self.d0 * h[2] + self.d1 * h[3]
    }

    /// The power-form coefficients.
    #[inline]
    pub fn power(&self) -> Power {
        let (p0, p1, d0, d1) = (self.p0, self.p1, self.d0, self.d1);
        Power {
            c: [
                p0,
                d0,
                3.0 * (p1 - p0) - 2.0 * d0 - d1,
                2.0 * (p0 - p1) + d0 + d1,
            ],
        }
    }

    /// The Bézier control points.
    #[inline]
    pub fn bezier(&self) -> Bezier {
        Bezier {
            b: [
                self.p0,
                self.p0 + self.d0 / 3.0,
                self.p1 - self.d1 / 3.0,
                self.p1,
            ],
        }
    }
}

/// A cubic in power form, `γ(λ) = c₀ + c₁λ + c₂λ² + c₃λ³`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Power {
    pub c: [DVec3; 4],
}

impl Power {
    /// `γ(λ)`.
    #[inline(always)]
    pub fn value(&self, l: f64) -> DVec3 {
        let c = &self.c;
        c[0] + l * (c[1] + l * (c[2] + l * c[3]))
    }

    /// `γ′(λ)`.
    #[inline(always)]
    pub fn d1(&self, l: f64) -> DVec3 {
        let c = &self.c;
        c[1] + l * (2.0 * c[2] + l * (3.0 * c[3]))
    }

    /// `γ″(λ)`.
    #[inline(always)]
    pub fn d2(&self, l: f64) -> DVec3 {
        2.0 * self.c[2] + (6.0 * l) * self.c[3]
    }

    /// `γ‴` (constant).
    #[inline(always)]
    pub fn d3(&self) -> DVec3 {
        6.0 * self.c[3]
    }

    /// `(γ, γ′, γ″)` at `λ`.
    #[inline(always)]
    pub fn at(&self, l: f64) -> (DVec3, DVec3, DVec3) {
        (self.value(l), self.d1(l), self.d2(l))
    }
}

/// A cubic Bézier curve by its four control points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bezier {
    pub b: [DVec3; 4],
}

impl Bezier {
    #[inline]
    pub fn new(b: [DVec3; 4]) -> Self {
        Bezier { b }
    }

    /// The Hermite data of the same cubic.
    #[inline]
    pub fn hermite(&self) -> Hermite {
        let b = &self.b;
        Hermite {
            p0: b[0],
            p1: b[3],
            d0: 3.0 * (b[1] - b[0]),
            d1: 3.0 * (b[3] - b[2]),
        }
    }

    /// The legs `[b₁ − b₀, b₂ − b₁, b₃ − b₂]`.
    #[inline]
    pub fn legs(&self) -> [DVec3; 3] {
        [
            self.b[1] - self.b[0],
            self.b[2] - self.b[1],
            self.b[3] - self.b[2],
        ]
    }

    /// `γ(v)` (de Casteljau).
    #[inline]
    pub fn point(&self, v: f64) -> DVec3 {
        let [p0, p1, p2, p3] = self.b;
        let a = p0.lerp(p1, v);
        let b = p1.lerp(p2, v);
        let c = p2.lerp(p3, v);
        let d = a.lerp(b, v);
        let e = b.lerp(c, v);
        d.lerp(e, v)
    }

    /// `γ′(v) = 3 Σ dᵢ Bᵢ²(v)`.
    #[inline]
    pub fn d1(&self, v: f64) -> DVec3 {
        let [d1, d2, d3] = self.legs();
        let w = bern2(v);
        3.0 * (d1 * w[0] + d2 * w[1] + d3 * w[2])
    }

    /// `γ″(v) = 6((d₂ − d₁)(1 − v) + (d₃ − d₂)v)`.
    #[inline]
    pub fn d2(&self, v: f64) -> DVec3 {
        let [d1, d2, d3] = self.legs();
        6.0 * ((d2 - d1) * (1.0 - v) + (d3 - d2) * v)
    }

    /// `γ‴ = 6(d₃ − 2d₂ + d₁)`.
    #[inline]
    pub fn d3(&self) -> DVec3 {
        let [d1, d2, d3] = self.legs();
        6.0 * (d3 - 2.0 * d2 + d1)
    }

    /// Derivative of order `k` at `v` (0 the point; zero above 3).
    #[inline]
    pub fn derivative(&self, k: usize, v: f64) -> DVec3 {
        match k {
            0 => self.point(v),
            1 => self.d1(v),
            2 => self.d2(v),
            3 => self.d3(),
            _ => DVec3::ZERO,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn data() -> Hermite {
        Hermite::new(
            DVec3::new(0.3, -1.0, 2.0),
            DVec3::new(1.7, 0.4, 1.1),
            DVec3::new(2.0, 1.5, -0.5),
            DVec3::new(-0.3, 2.2, 0.9),
        )
    }

    fn close(a: DVec3, b: DVec3, tol: f64) -> bool {
        (a - b).length() <= tol * (1.0 + b.length())
    }

    #[test]
    fn every_form_reproduces_the_hermite_data() {
        let h = data();
        let (p, b) = (h.power(), h.bezier());
        for (v0, v1, s0, s1) in [
            (h.value(0.0), h.value(1.0), h.slope(0.0), h.slope(1.0)),
            (p.value(0.0), p.value(1.0), p.d1(0.0), p.d1(1.0)),
            (b.point(0.0), b.point(1.0), b.d1(0.0), b.d1(1.0)),
        ] {
            assert!(close(v0, h.p0, 1e-15) && close(v1, h.p1, 1e-15));
            assert!(close(s0, h.d0, 1e-15) && close(s1, h.d1, 1e-15));
        }
    }

    #[test]
    fn the_forms_agree_everywhere() {
        let h = data();
        let (p, b) = (h.power(), h.bezier());
        for i in 0..=10 {
            let l = i as f64 / 10.0;
            assert!(close(p.value(l), h.value(l), 1e-14));
            assert!(close(b.point(l), h.value(l), 1e-14));
            assert!(close(p.d1(l), h.slope(l), 1e-14));
            assert!(close(b.d1(l), h.slope(l), 1e-14));
            assert!(close(b.d2(l), p.d2(l), 1e-14));
            assert!(close(b.d3(), p.d3(), 1e-14));
            for k in 0..4 {
                let want = [p.value(l), p.d1(l), p.d2(l), p.d3()][k];
                assert!(close(b.derivative(k, l), want, 1e-14));
            }
            assert_eq!(b.derivative(4, l), DVec3::ZERO);
        }
    }

    #[test]
    fn derivatives_match_central_differences() {
        let h = data();
        let (p, b) = (h.power(), h.bezier());
        let e = 1e-5;
        for l in [0.1, 0.37, 0.5, 0.81] {
            let fd = |f: &dyn Fn(f64) -> DVec3| (f(l + e) - f(l - e)) / (2.0 * e);
            // the central difference of a cubic errs by e² γ‴/6 (γ‴ is constant)
            let tol = 1e-8;
            assert!(close(fd(&|x| h.value(x)), h.slope(l), tol));
            assert!(close(fd(&|x| p.value(x)), p.d1(l), tol));
            assert!(close(fd(&|x| p.d1(x)), p.d2(l), tol));
            assert!(close(fd(&|x| p.d2(x)), p.d3(), tol));
            assert!(close(fd(&|x| b.point(x)), b.d1(l), tol));
            assert!(close(fd(&|x| b.d1(x)), b.d2(l), tol));
            assert!(close(fd(&|x| b.d2(x)), b.d3(), tol));
            let (v, dv) = basis(l);
            let (vp, _) = basis(l + e);
            let (vm, _) = basis(l - e);
            for k in 0..4 {
                assert!(((vp[k] - vm[k]) / (2.0 * e) - dv[k]).abs() < tol);
            }
            // φ₀ + φ₁ = 1 (constants are reproduced)
            assert!((v[0] + v[1] - 1.0).abs() < 1e-15);
        }
    }

    #[test]
    fn bezier_and_hermite_round_trip() {
        let h = data();
        let back = h.bezier().hermite();
        for (a, b) in [
            (back.p0, h.p0),
            (back.p1, h.p1),
            (back.d0, h.d0),
            (back.d1, h.d1),
        ] {
            assert!(close(a, b, 1e-15));
        }
        let b = Bezier::new([DVec3::ZERO, DVec3::X, DVec3::new(2.0, 1.0, 0.0), DVec3::ONE]);
        let again = b.hermite().bezier();
        for i in 0..4 {
            assert!(close(again.b[i], b.b[i], 1e-15));
        }
    }

    #[test]
    fn bernstein_weights_sum_to_one() {
        for v in [0.0, 0.25, 0.6, 1.0] {
            let w = bern2(v);
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        }
    }
}
