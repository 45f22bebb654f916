//! The axis curve of a strip along a curve ([`super::tube`]) or of a rod ([`super::rod`]),
//! and its nearest points (foot points).
//!
//! **Axis.** The C¹ piecewise cubic Hermite curve through the samples `x_k` with derivatives
//! `m_k = dγ/dS` at the cumulative chord lengths `S_k` (`spinal.fields.strip_curve` uses the
//! clamped C² cubic spline's derivatives, [`clamped_spline_slopes`], so `γ` is C²). Segment
//! `k`, `λ ∈ [0, 1]`: `γ(λ) = a + bλ + cλ² + dλ³` with `a = x_k`, `b = m_k ΔS_k`,
//! `c = 3(x_{k+1} − x_k) − (2m_k + m_{k+1}) ΔS_k`, `d = 2(x_k − x_{k+1}) + (m_k + m_{k+1}) ΔS_k`.
//!
//! **Where it is valid.** The foot point must be unique within `r < ρ + R_f`: curvature times
//! `ρ + R_f + segment arc length` below 1 (checked here on 16 points per segment; it also makes
//! `(X − γ)·γ′` monotone on every segment within reach, so one bracketed root per segment)
//! and no approach of distant parts of the axis closer than `2(ρ + R_f)`: no two of the 16
//! points per segment closer than that whose chord-length parameters differ by more than
//! `π(ρ + R_f)` ([`self_approach`], a uniform grid of cells of size `2(ρ + R_f)`, the classic
//! fixed-radius near-neighbour search; Bentley, Stanat and Williams, "The complexity of
//! finding fixed-radius near neighbors", Inf. Proc. Letters 6 (1977)). Both name `points`, the
//! samples the axis was built from. The foot point is found by safeguarded Newton on
//! `F(λ) = (X − γ(λ))·γ′(λ)` in each segment whose Bézier hull is within reach and whose end
//! values bracket a root; the nearest candidate wins.

use glam::DVec3;

use crate::error::{InputError, Result};
use crate::math::cubic::{Hermite, Power};
use crate::run::alloc;
use crate::run::cancel::{self, Cancel};

/// One axis sample: position, derivative `dγ/dS`, cumulative chord length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisSample {
    /// Position `γ` on the axis (world units).
    pub x: DVec3,
    /// Derivative `dγ/dS` (per unit chord length).
    pub m: DVec3,
    /// Cumulative chord length `S`.
    pub s: f64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Segment {
    /// `γ(λ)` in power form.
    curve: Power,
    /// Bounding sphere of the Bézier hull.
    centre: DVec3,
    radius: f64,
    /// The point-independent coefficients of the foot-point equation ([`Segment::quintic`]):
    /// `−|c₁|²`, `−3c₁·c₂`, `−(4c₁·c₃ + 2|c₂|²)`, `−5c₂·c₃`, `−3|c₃|²`.
    k: [f64; 5],
}

impl Segment {
    fn new(curve: Power, centre: DVec3, radius: f64) -> Segment {
        let [_, c1, c2, c3] = curve.c;
        let k = [
            -c1.dot(c1),
            -3.0 * c1.dot(c2),
            -(4.0 * c1.dot(c3) + 2.0 * c2.dot(c2)),
            -5.0 * c2.dot(c3),
            -3.0 * c3.dot(c3),
        ];
        Segment {
            curve,
            centre,
            radius,
            k,
        }
    }

    #[inline(always)]
    fn at(&self, l: f64) -> (DVec3, DVec3, DVec3) {
        self.curve.at(l)
    }

    /// `F(λ) = (X − γ(λ))·γ′(λ)` as a quintic in `λ`, coefficients `a₀ … a₅`. With
    /// `γ = c₀ + c₁λ + c₂λ² + c₃λ³` and `Y = X − c₀` (the segment's own origin, so that the
    /// terms stay of the size of `|X − γ|`, not of the coordinates):
    /// `Y·γ′ = Y·c₁ + 2Y·c₂ λ + 3Y·c₃ λ²` and
    /// `(γ − c₀)·γ′ = |c₁|²λ + 3c₁·c₂ λ² + (4c₁·c₃ + 2|c₂|²)λ³ + 5c₂·c₃ λ⁴ + 3|c₃|² λ⁵`.
    #[inline(always)]
    fn quintic(&self, x: DVec3) -> [f64; 6] {
        let [c0, c1, c2, c3] = self.curve.c;
        let y = x - c0;
        let k = &self.k;
        [
            y.dot(c1),
            2.0 * y.dot(c2) + k[0],
            3.0 * y.dot(c3) + k[1],
            k[2],
            k[3],
            k[4],
        ]
    }
}

/// A smooth axis curve through samples: the piecewise cubic Hermite `γ`, checked for a tube
/// of radius `outer` about it (the foot point of every point within `outer` is unique), with
/// the closest-point query. Shared by the curved strip and the rod of [`super::rod`].
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// The samples: positions, derivatives `dγ/dS`, cumulative chord lengths.
    pub samples: Vec<AxisSample>,
    segs: Vec<Segment>,
    /// A sphere (`centre`, `bound`) containing every segment's hull.
    centre: DVec3,
    bound: f64,
    /// The segments by blocks of [`BLOCK`], for [`Axis::closest_point`]'s scan.
    blocks: Vec<Block>,
}

/// Segments per block of the scan of [`Axis::closest_point`] (at most 31: a block's
/// sign pattern is a `u32` with one bit per sample).
const BLOCK: usize = 16;

/// The planes stored per block: `BLOCK + 1` rounded up to whole groups of [`GROUP`].
const PLANES: usize = (BLOCK + 1).div_ceil(GROUP) * GROUP;

/// Planes evaluated together in [`Axis::closest_point`]'s scan (a vector's width).
const GROUP: usize = 4;

/// [`BLOCK`] consecutive segments of an [`Axis`] (fewer in the last block).
#[derive(Debug, Clone, PartialEq)]
struct Block {
    /// The axis-aligned box of the segments' Bézier hulls: a point at least `outer` outside
    /// it in one coordinate is at least `outer` from every segment and sample of the block.
    lo: DVec3,
    hi: DVec3,
    /// The normal planes `F_k = X·m_k − x_k·m_k` at the block's first `BLOCK + 1` samples,
    /// as `m_k·x`, `m_k·y`, `m_k·z` and `x_k·m_k` (zeros past the last sample, up to
    /// [`PLANES`]).
    planes: [[f64; PLANES]; 4],
    /// The number of segments in the block.
    segs: usize,
}

/// The nearest point of an [`Axis`] to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Foot {
    /// On segment `k` at local parameter `λ`.
    Segment(usize, f64),
    /// An end sample (the point lies beyond the end's normal plane).
    Cap(usize),
}

impl Axis {
    /// The axis through `samples`, checked for a tube of radius `outer`: at least 2
    /// samples, non-zero derivatives, increasing `S`, no cusp, curvature × (outer + segment
    /// arc) below 1 and no approach of distant parts closer than `2·outer` (errors name
    /// `points`).
    ///
    /// Polls `cancel` every [`cancel::BLOCK`] segments and in the self-approach search, and fails
    /// with [`InputError::stopped`] once it says stop.
    // Kept whole: the checks and the segment and block tables are built in the same passes
    // over the samples, polled per block, in the order the error messages follow.
    pub fn new(samples: Vec<AxisSample>, outer: f64, cancel: Cancel<'_>) -> Result<Axis> {
        let bad = |m: String| InputError::new("points", m);
        let axis = bad;
        if samples.len() < 2 {
            return Err(axis("a strip axis needs at least 2 samples".into()));
        }
        for (i, p) in samples.iter().enumerate() {
            if !(p.m.length() > 0.0) {
                return Err(bad(format!("strip axis derivative {i} is zero")));
            }
        }
        const CALL: &str = "strip_curve/rod axis";
        let mut segs = alloc::with_capacity(CALL, samples.len() - 1)?;
        let mut blocks: Vec<Block> = alloc::with_capacity(CALL, (samples.len() - 2) / BLOCK + 1)?;
        // the axis at `PER` parameters per segment (and the last sample), with their
        // chord-length parameters, for the self-approach check
        let rows = alloc::product(CALL, PER, samples.len() - 1, size_of::<DVec3>())? + 1;
        let mut dense = alloc::with_capacity(CALL, rows)?;
        let mut param = alloc::with_capacity(CALL, rows)?;
        // (segment, curvature × (radius + reach + arc), curvature) of the worst bend
        let mut worst: (usize, f64, f64) = (0, 0.0, 0.0);
        for (k, w) in samples.windows(2).enumerate() {
            if k % cancel::BLOCK == 0 && cancel() {
                return Err(InputError::stopped());
            }
            let ds = w[1].s - w[0].s;
            if !(ds > 0.0) {
                return Err(bad(format!(
                    "strip axis arc length must increase strictly (segment {k})"
                )));
            }
            let x0 = w[0].x;
            let data = Hermite::new(x0, w[1].x, w[0].m * ds, w[1].m * ds);
            let hull = data.bezier().b;
            let centre = 0.25 * (hull[0] + hull[1] + hull[2] + hull[3]);
            let radius = hull
                .iter()
                .map(|p| (*p - centre).length())
                .fold(0.0, f64::max);
            let seg = Segment::new(data.power(), centre, radius);
            let (lo, hi) = hull
                .iter()
                .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
                    (lo.min(*p), hi.max(*p))
                });
            if k % BLOCK == 0 {
                let mut planes = [[0.0; PLANES]; 4];
                for (j, p) in samples[k..].iter().take(BLOCK + 1).enumerate() {
                    for (a, v) in [p.m.x, p.m.y, p.m.z, p.x.dot(p.m)].into_iter().enumerate() {
                        planes[a][j] = v;
                    }
                }
                blocks.push(Block {
                    lo,
                    hi,
                    planes,
                    segs: 1,
                });
            } else if let Some(b) = blocks.last_mut() {
                b.lo = b.lo.min(lo);
                b.hi = b.hi.max(hi);
                b.segs += 1;
            }
            // curvature-like bound |γ″|/|γ′|² and the arc length, on 16 sub-intervals
            let mut kmax: f64 = 0.0;
            let mut arc = 0.0;
            let mut prev = x0;
            for i in 0..=PER {
                let l = i as f64 / PER as f64;
                let (g, g1, g2) = seg.at(l);
                let s2 = g1.length_squared();
                if !(s2 > 0.0) {
                    return Err(axis(format!("the axis has a cusp in segment {k}")));
                }
                kmax = kmax.max(g2.length() / s2);
                arc += (g - prev).length();
                prev = g;
                if i < PER {
                    dense.push(g);
                    param.push(w[0].s + ds * l);
                }
            }
            let w = kmax * (outer + 1.01 * arc);
            // the worst segment (the first NaN, else the largest) is the one reported
            if !worst.1.is_nan() && (w.is_nan() || w > worst.1) {
                worst = (k, w, kmax);
            }
            segs.push(seg);
        }
        if !(worst.1 < 1.0) {
            let (k, w, kmax) = worst;
            return Err(axis(format!(
                "the axis bends too sharply in segment {k}: curvature {} × (radius + reach + \
                 segment length) = {} must stay below 1 (use a smaller radius or reach, or \
                 sample the bend more finely)",
                g4(kmax),
                g4(w)
            )));
        }
        let last = samples[samples.len() - 1];
        dense.push(last.x);
        param.push(last.s);
        let approach = self_approach(&dense, &param, outer, cancel);
        if cancel() {
            return Err(InputError::stopped());
        }
        if let Some((i, j, d)) = approach {
            let seg = |i: usize| (i / PER).min(segs.len() - 1);
            return Err(axis(format!(
                "the axis comes within {} < 2·(radius + reach) = {} of itself (segments {} \
                 and {}); the closest point would be ambiguous",
                g4(d),
                g4(2.0 * outer),
                seg(i),
                seg(j)
            )));
        }
        let lo = segs
            .iter()
            .fold(DVec3::INFINITY, |m, g| m.min(g.centre - g.radius));
        let hi = segs
            .iter()
            .fold(DVec3::NEG_INFINITY, |m, g| m.max(g.centre + g.radius));
        let centre = 0.5 * (lo + hi);
        let bound = segs
            .iter()
            .map(|g| (g.centre - centre).length() + g.radius)
            .fold(0.0, f64::max);
        Ok(Axis {
            samples,
            segs,
            centre,
            bound,
            blocks,
        })
    }

    /// The root of `F(λ) = (X − γ)·γ′` in `[0, 1]`, given `F(0) ≥ 0 > F(1)`: safeguarded
    /// Newton on the quintic [`Segment::quintic`] (Horner's rule for `F` and
    /// `F′ = −|γ′|² + (X − γ)·γ″`), bisection where a Newton step leaves the bracket.
    #[inline]
    fn foot(seg: &Segment, x: DVec3, f0: f64, f1: f64) -> f64 {
        let a = seg.quintic(x);
        let (b1, b2, b3, b4) = (2.0 * a[2], 3.0 * a[3], 4.0 * a[4], 5.0 * a[5]);
        let (mut lo, mut hi) = (0.0, 1.0);
        let mut l = (f0 / (f0 - f1)).clamp(0.0, 1.0);
        for _ in 0..64 {
            let f = a[0] + l * (a[1] + l * (a[2] + l * (a[3] + l * (a[4] + l * a[5]))));
            if f == 0.0 {
                break;
            }
            if f >= 0.0 {
                lo = l;
            } else {
                hi = l;
            }
            let df = a[1] + l * (b1 + l * (b2 + l * (b3 + l * b4)));
            let newton = l - f / df;
            if df < 0.0 && newton >= lo && newton <= hi {
                let step = (newton - l).abs();
                l = newton;
                // quadratic convergence: after a Newton step δ ≤ 1e-9 the error is O(δ²)
                if !(step > 1e-9) {
                    break;
                }
            } else {
                l = 0.5 * (lo + hi);
                if !(hi - lo > 1e-16) {
                    break;
                }
            }
        }
        l
    }

    /// The foot point of `x` within `outer` of the axis (the nearest candidate: a foot on a
    /// segment or an end cap), if any.
    #[inline]
    pub fn closest(&self, x: DVec3, outer: f64) -> Option<Foot> {
        self.closest_point(x, outer).map(|(f, _)| f)
    }

    /// [`Self::closest`] with the foot's point. `F_k = (X − x_k)·m_k` is evaluated at the
    /// samples in blocks of [`BLOCK`] (a vectorisable loop; a block is skipped when `x` is
    /// `outer` outside its segments' box); a segment is a candidate only where `F` changes
    /// sign from `≥ 0` to `< 0` across it (then the bounding-sphere cull, then Newton), an
    /// end cap only beyond its plane.
    #[inline(always)]
    pub fn closest_point(&self, x: DVec3, outer: f64) -> Option<(Foot, DVec3)> {
        let o2 = outer * outer;
        let n = self.samples.len();
        let lim = self.bound + outer;
        if !((x - self.centre).length_squared() < lim * lim) {
            return None;
        }
        let mut best = o2;
        let mut hit = None;
        let last = self.blocks.len() - 1;
        for (b, blk) in self.blocks.iter().enumerate() {
            // no segment or end cap of this block within `outer`
            if (x.cmple(blk.lo - outer) | x.cmpge(blk.hi + outer)).any() {
                continue;
            }
            let [bx, by, bz, bc] = &blk.planes;
            // by groups of a vector's width (the zeros past the block's samples read as
            // `F ≥ 0`, above the bits of the candidates)
            let mut f = [0.0; PLANES];
            let mut pos = 0u32;
            for g in 0..PLANES / GROUP {
                let mut bits = 0u32;
                for i in 0..GROUP {
                    let j = g * GROUP + i;
                    let fj = (x.x * bx[j] + x.y * by[j]) + (x.z * bz[j] - bc[j]);
                    f[j] = fj;
                    bits |= ((fj >= 0.0) as u32) << i;
                }
                pos |= bits << (g * GROUP);
            }
            if b == 0 && f[0] < 0.0 {
                let p0 = self.samples[0].x;
                let r2 = (x - p0).length_squared();
                if r2 < best {
                    best = r2;
                    hit = Some((Foot::Cap(0), p0));
                }
            }
            let mut cand = pos & !(pos >> 1) & ((1u32 << blk.segs) - 1);
            while cand != 0 {
                let j = cand.trailing_zeros() as usize;
                cand &= cand - 1;
                let k = b * BLOCK + j;
                let seg = &self.segs[k];
                let lim = seg.radius + outer;
                if (x - seg.centre).length_squared() < lim * lim {
                    let l = Self::foot(seg, x, f[j], f[j + 1]);
                    let g = seg.curve.value(l);
                    let r2 = (x - g).length_squared();
                    if r2 < best {
                        best = r2;
                        hit = Some((Foot::Segment(k, l), g));
                    }
                }
            }
            if b == last && f[blk.segs] >= 0.0 {
                let pn = self.samples[n - 1].x;
                if (x - pn).length_squared() < best {
                    hit = Some((Foot::Cap(n - 1), pn));
                }
            }
        }
        hit
    }

    /// Whether a point of the box `[lo, hi]` may be within `outer` of the axis: `false` when
    /// [`Self::closest_point`] is certain to return `None` at every point of the box (each
    /// segment's bounding-sphere cull and each end cap's test fail there). The squared
    /// distance from the box to a point, `Σ max(lo − c, c − hi, 0)²` summed in the order of
    /// [`DVec3::length_squared`], is at most the rounded `|x − c|²` of every `x` in the box
    /// (rounding is monotone), so the test is exact in floating point, not only in reals.
    /// Used once per batch of lock-step path lines, which the spatial order keeps close.
    pub fn may_reach(&self, lo: DVec3, hi: DVec3, outer: f64) -> bool {
        #[inline(always)]
        fn d2(lo: DVec3, hi: DVec3, c: DVec3) -> f64 {
            (lo - c).max(c - hi).max(DVec3::ZERO).length_squared()
        }
        let lim = self.bound + outer;
        if !(d2(lo, hi, self.centre) < lim * lim) {
            return false;
        }
        let o2 = outer * outer;
        let n = self.samples.len();
        if d2(lo, hi, self.samples[0].x) < o2 || d2(lo, hi, self.samples[n - 1].x) < o2 {
            return true;
        }
        for (b, blk) in self.blocks.iter().enumerate() {
            if (hi.cmple(blk.lo - outer) | lo.cmpge(blk.hi + outer)).any() {
                continue;
            }
            for seg in &self.segs[b * BLOCK..b * BLOCK + blk.segs] {
                let lim = seg.radius + outer;
                if d2(lo, hi, seg.centre) < lim * lim {
                    return true;
                }
            }
        }
        false
    }

    /// `γ`, `γ′`, `γ″` (in the local parameter) of segment `k` at `λ`.
    #[inline]
    pub fn at(&self, k: usize, l: f64) -> (DVec3, DVec3, DVec3) {
        self.segs[k].at(l)
    }

    /// The point of a foot.
    #[inline]
    pub fn point(&self, foot: Foot) -> DVec3 {
        match foot {
            Foot::Segment(k, l) => self.segs[k].at(l).0,
            Foot::Cap(e) => self.samples[e].x,
        }
    }

    /// The largest distance from `c` of a point of the axis's segment hulls.
    pub fn extent_about(&self, c: DVec3) -> f64 {
        self.segs
            .iter()
            .map(|g| (g.centre - c).length() + g.radius)
            .fold(0.0, f64::max)
    }
}

/// Derivatives `dγ/dS` at the knots of the clamped C² cubic spline through `x` at the
/// increasing parameters `s`, with end derivatives `m0`, `m1` (de Boor, "A Practical Guide to
/// Splines", Ch. IV: the tridiagonal system for the slopes, solved by the Thomas algorithm;
/// strictly diagonally dominant, so no pivoting). Row `k` (`1 ≤ k ≤ n − 2`, `h_k = s_{k+1} − s_k`,
/// `δ_k = (x_{k+1} − x_k)/h_k`):
/// `h_k m_{k−1} + 2(h_{k−1} + h_k) m_k + h_{k−1} m_{k+1} = 3(h_k δ_{k−1} + h_{k−1} δ_k)`.
/// `x` and `s` have the same length ≥ 2.
pub fn clamped_spline_slopes(x: &[DVec3], s: &[f64], m0: DVec3, m1: DVec3) -> Result<Vec<DVec3>> {
    const CALL: &str = "strip_curve/rod axis";
    let n = x.len();
    let mut m = alloc::filled(CALL, n, DVec3::ZERO)?;
    m[0] = m0;
    m[n - 1] = m1;
    if n <= 2 {
        return Ok(m);
    }
    let h = alloc::collect(CALL, s.windows(2).map(|w| w[1] - w[0]))?;
    let delta = |k: usize| (x[k + 1] - x[k]) / h[k];
    // interior row i is knot k = i + 1: lower h_{i+1}, diagonal 2(h_i + h_{i+1}), upper h_i
    let k = n - 2;
    let mut c = alloc::filled(CALL, k, 0.0)?;
    let mut d = alloc::filled(CALL, k, DVec3::ZERO)?;
    let rhs = |i: usize| {
        let mut r = 3.0 * (h[i + 1] * delta(i) + h[i] * delta(i + 1));
        if i == 0 {
            r -= h[1] * m0;
        }
        if i == k - 1 {
            r -= h[k - 1] * m1;
        }
        r
    };
    let diag = |i: usize| 2.0 * (h[i] + h[i + 1]);
    c[0] = h[0] / diag(0);
    d[0] = rhs(0) / diag(0);
    for i in 1..k {
        let w = diag(i) - h[i + 1] * c[i - 1];
        c[i] = h[i] / w;
        d[i] = (rhs(i) - h[i + 1] * d[i - 1]) / w;
    }
    for i in (0..k - 1).rev() {
        d[i] = d[i] - c[i] * d[i + 1];
    }
    m[1..n - 1].copy_from_slice(&d);
    Ok(m)
}

/// The axis samples of a tube about `points`: at least 2 finite samples with no repeated
/// consecutive point, parametrised by cumulative chord length `S`, with the derivatives of
/// the clamped C² cubic spline through them ([`clamped_spline_slopes`]) whose end derivatives
/// are the five-point unit tangents of `spinal.estimate_tangents` (errors name `points`).
///
/// Polls `cancel` in its passes over the points and fails with [`InputError::stopped`] once it says
/// stop.
pub fn axis_samples(points: &[DVec3], cancel: Cancel<'_>) -> Result<Vec<AxisSample>> {
    if points.len() < 2 {
        return Err(InputError::new(
            "points",
            format!("need at least 2 samples, got {}", points.len()),
        ));
    }
    super::finite_rows("points", points)?;
    let mut s = alloc::with_capacity("strip_curve/rod axis", points.len())?;
    s.push(0.0);
    for (i, w) in points.windows(2).enumerate() {
        if i % cancel::BLOCK == 0 && cancel() {
            return Err(InputError::stopped());
        }
        let chord = w[0].distance(w[1]);
        if !(chord > 0.0) {
            return Err(InputError::new(
                "points",
                format!("consecutive samples {i} and {} coincide", i + 1),
            ));
        }
        s.push(s[i] + chord);
    }
    let tangents = crate::frames::tangents::estimate_rows(
        points,
        false,
        crate::frames::TangentRule::FivePointBounded,
        cancel,
    )?;
    if cancel() {
        return Err(InputError::stopped());
    }
    let m = clamped_spline_slopes(points, &s, tangents[0], tangents[points.len() - 1])?;
    alloc::collect(
        "strip_curve/rod axis",
        points
            .iter()
            .zip(&m)
            .zip(&s)
            .map(|((&x, &m), &s)| AxisSample { x, m, s }),
    )
}

/// Points per segment at which the axis is checked.
const PER: usize = 16;

/// `x` with 4 significant digits, like C's `%.4g`.
pub(super) fn g4(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    if !(1e-4..1e4).contains(&a) {
        return format!("{x:.3e}");
    }
    let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
    let s = format!("{x:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// The first pair `(i, j, |p_i − p_j|)` (smallest `i`, then smallest `j`) of points of the
/// polyline `p` closer than `2·outer` whose parameters `t` (increasing) differ by more than
/// `π·outer`; `None` if there is none.
///
/// Fixed-radius near neighbours on a uniform grid of cells of size `2·outer`: a point's
/// partners lie in its own cell or the 26 around it. A cell keeps the runs of consecutive
/// indices that pass through it. Along a run, the polyline length `L` bounds the chord,
/// `|p_i − p_j′| ≥ |p_i − p_j| − (L_j′ − L_j)`, so after a point at distance `d ≥ 2·outer`
/// the scan jumps (binary search on `L`) to the first point at least `d − 2·outer` further
/// along: a finely sampled axis costs O(log) per run and point, not its sampling density.
/// The search polls `cancel` every [`cancel::BLOCK`] points and returns `None` once it says
/// stop (the caller checks `cancel` again).
pub(super) fn self_approach(
    p: &[DVec3],
    t: &[f64],
    outer: f64,
    cancel: Cancel<'_>,
) -> Option<(usize, usize, f64)> {
    use std::collections::HashMap;
    let n = p.len();
    if n < 2 {
        return None;
    }
    let two = 2.0 * outer;
    let near = std::f64::consts::PI * outer;
    // `len` and the cells' runs are at most the size of `p`, the strip's dense axis, which
    // was allocated fallibly just before (this check has no error path of its own)
    let mut len = Vec::with_capacity(n);
    let mut acc = 0.0;
    len.push(acc);
    for w in p.windows(2) {
        acc += (w[1] - w[0]).length();
        len.push(acc);
    }
    // rounding in `L` (a sum of up to n lengths) must never make the scan skip a point
    let slack = 1e-9 * acc;
    let lo = p.iter().fold(DVec3::INFINITY, |m, x| m.min(*x));
    // `as` saturates: far-out points share the outermost cells, which is still correct
    let key = |x: DVec3| {
        let q = ((x - lo) / two).floor();
        [q.x as i64, q.y as i64, q.z as i64]
    };
    // the maximal runs of consecutive indices in each cell (one hash per run, not per point)
    let mut cells: HashMap<[i64; 3], Vec<(usize, usize)>> = HashMap::new();
    let mut run = (key(p[0]), 0);
    for (i, x) in p.iter().enumerate().skip(1) {
        if i % cancel::BLOCK == 0 && cancel() {
            return None;
        }
        let k = key(*x);
        if k != run.0 {
            cells.entry(run.0).or_default().push((run.1, i));
            run = (k, i);
        }
    }
    cells.entry(run.0).or_default().push((run.1, n));
    let mut around: Vec<(usize, usize)> = Vec::new();
    let mut here = None;
    let mut first = 0; // the first index with t > t_i + π·outer
    for i in 0..n {
        if i % cancel::BLOCK == 0 && cancel() {
            return None;
        }
        let k = key(p[i]);
        if here != Some(k) {
            here = Some(k);
            around.clear();
            let mut seen: Vec<[i64; 3]> = Vec::with_capacity(27);
            for dx in -1..=1i64 {
                for dy in -1..=1i64 {
                    for dz in -1..=1i64 {
                        let c = [
                            k[0].saturating_add(dx),
                            k[1].saturating_add(dy),
                            k[2].saturating_add(dz),
                        ];
                        if seen.contains(&c) {
                            continue;
                        }
                        seen.push(c);
                        if let Some(runs) = cells.get(&c) {
                            around.extend_from_slice(runs);
                        }
                    }
                }
            }
        }
        while first < n && !(t[first] > t[i] + near) {
            first += 1;
        }
        let mut hit: Option<(usize, f64)> = None;
        for &(a, b) in &around {
            let mut j = a.max(first);
            let end = hit.map_or(b, |(h, _)| b.min(h));
            while j < end {
                let d = (p[j] - p[i]).length();
                if d < two {
                    hit = Some((j, d));
                    break;
                }
                let gap = d - two - slack;
                j += 1;
                if gap > 0.0 && j < end {
                    j += len[j..end].partition_point(|&l| l - len[j - 1] <= gap);
                }
            }
        }
        if let Some((j, d)) = hit {
            return Some((i, j, d));
        }
    }
    None
}

#[cfg(test)]
pub(super) mod tests;
