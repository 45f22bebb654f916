//! The discrete spine model (see the module docs of [`crate::flesh`]): positions the cubic
//! Hermite interpolant of the samples with end slopes `h_k t_j` (`h_k` the chord); unit
//! tangents `t(a) = m(a)/|m(a)|` with `m` the cubic Hermite interpolant of the sample
//! tangents whose end derivatives are `σ_k κ_j` (`κ_j` the sample curvature vectors from
//! central differences of the tangents in chord length, `σ_k = E_k·t_j`), so that the
//! model's curvature vector `κ = (dt/da)/σ` equals `κ_j` at sample `j` from both sides: the
//! map is continuous across samples (up to the O(h³) jump of `σ`); RMF reference vectors
//! blended in the normal plane of `t_k` and carried to `t(a)` by the minimal rotation.

use glam::{DVec2, DVec3};

use crate::error::{InputError, Result};
use crate::math::cubic::{Hermite, Power};
use crate::math::rotation::minimal_rotate;
use crate::math::scale::{self, Pow2};
use crate::run::alloc;
use crate::run::cancel::{self, Cancel};

/// A sampled spine with its frames (`t` and `r` columns of `spinal.frames`).
///
/// The model is built on the samples divided by their power-of-two scale
/// ([`scale::curve_exponent`]; "model units", exact): lengths enter its arithmetic squared
/// (chords, distances) and as products with curvatures, which leave the range of f64 for
/// spines far from unit size although the input is fine.
#[derive(Clone, Debug)]
pub struct SpineModel {
    /// Input units to model units (`2^k`, 1 for spines of moderate size).
    pub scale: Pow2,
    /// Sample points `C_j` (model units).
    pub c: Vec<DVec3>,
    /// Unit tangents `t_j` at the samples (the `t` columns of the frames).
    pub t: Vec<DVec3>,
    /// RMF reference vectors `r_j` at the samples (the `r` columns).
    pub r: Vec<DVec3>,
    /// Per edge: `m(a)` in power form.
    pub m: Vec<Power>,
    /// Per edge: the position `C(a)` in the same power form.
    pub p: Vec<Power>,
    /// Per edge: `r_{k+1}` carried back to `t_k` by the minimal rotation.
    pub rb: Vec<DVec3>,
    /// A loop: the last sample repeats the first (the closing edge is the last edge) and
    /// there are no ends to extend.
    pub closed: bool,
}

/// Sample curvature vectors: central differences of the unit tangents in chord length,
/// made normal to the tangent (one-sided at the ends; across the seam of a loop, whose last
/// sample repeats the first).
fn curvatures(
    call: &'static str,
    c: &[DVec3],
    t: &[DVec3],
    closed: bool,
    cancel: Cancel<'_>,
) -> Result<Vec<DVec3>> {
    let n = c.len();
    let mut kv = alloc::try_collect(
        call,
        (0..n).map(|j| {
            cancel::poll(j, cancel)?;
            let (a, b) = (j.saturating_sub(1), (j + 1).min(n - 1));
            let mut len = 0.0;
            for i in a..b {
                len += (c[i + 1] - c[i]).length();
            }
            let k = (t[b] - t[a]) / len;
            Ok(k - t[j] * t[j].dot(k))
        }),
        // the items poll on their own and fail when stopped
        &cancel::never,
    )?;
    if closed && n >= 3 {
        // neighbours of the seam sample: n − 2 before it, 1 after it
        let len = (c[1] - c[0]).length() + (c[n - 1] - c[n - 2]).length();
        let k = (t[1] - t[n - 2]) / len;
        kv[0] = k - t[0] * t[0].dot(k);
        kv[n - 1] = kv[0];
    }
    Ok(kv)
}

/// The spine evaluated at `(k, a)`.
#[derive(Clone, Copy, Debug)]
pub struct Local {
    /// Position `C(a)` (model units).
    pub q: DVec3,
    /// Unit tangent `t(a)`.
    pub t: DVec3,
    /// Interpolated RMF reference vector (unit, ⟂ `t`).
    pub u: DVec3,
    /// `t × u`, completing the right-handed frame `(u, v, t)`.
    pub v: DVec3,
    /// `C'(a) · t(a)`: the speed of the sections along the spine.
    pub sigma: f64,
    /// Curvature vector (1/length, model units) in the `(u, v)` coordinates.
    pub kappa: DVec2,
}

impl SpineModel {
    /// `frames` is row-major `(n, 3, 3)` with columns `(r, s, t)` (the layout of the crate).
    /// `closed`: the spine is a loop given with its first sample (and frame) repeated at the
    /// end, so the closing edge is the last one.
    ///
    /// Polls `cancel` every [`cancel::BLOCK`] samples of its passes and fails with
    /// [`InputError::stopped`] once it says stop.
    pub fn new(
        arg: &'static str,
        points: &[DVec3],
        frames: &[f64],
        closed: bool,
        cancel: Cancel<'_>,
    ) -> Result<SpineModel> {
        let n = points.len();
        let min = if closed { 4 } else { 2 };
        if n < min {
            return Err(InputError::new(
                arg,
                format!("need at least {min} points, got {n}"),
            ));
        }
        if closed && points[0] != points[n - 1] {
            return Err(InputError::new(
                arg,
                "a loop must repeat its first point at the end",
            ));
        }
        if frames.len() != 9 * n {
            return Err(InputError::new(arg, "frames do not match the points"));
        }
        // the call, for out-of-memory errors
        let call = if arg == "rest_spine" {
            "SpineBinding"
        } else {
            "SpineBinding.deform"
        };
        let (lo, hi) = crate::frames::geometry::bounds(points);
        let k = scale::curve_exponent(lo, hi).unwrap_or(0);
        let to_model = Pow2::new(k);
        let pts = if k == 0 {
            alloc::copied(call, points)?
        } else {
            scale::try_scaled(call, points, k)?
        };
        let points = &pts[..];
        let mut t = alloc::with_capacity(call, n)?;
        let mut r = alloc::with_capacity(call, n)?;
        for (i, f) in frames.chunks_exact(9).enumerate() {
            cancel::poll(i, cancel)?;
            let ri = DVec3::new(f[0], f[3], f[6]);
            let ti = DVec3::new(f[2], f[5], f[8]);
            if !(ri.is_finite() && ti.is_finite() && points[i].is_finite()) {
                return Err(InputError::new(arg, format!("row {i} is not finite")));
            }
            t.push(ti);
            r.push(ri);
        }
        for k in 0..n - 1 {
            cancel::poll(k, cancel)?;
            let e = points[k + 1] - points[k];
            // σ = E·t(a) > 0 on the whole edge iff it is at both ends
            if !(e.dot(t[k]) > 0.0 && e.dot(t[k + 1]) > 0.0) {
                return Err(InputError::new(
                    arg,
                    format!(
                        "rows {k} and {}: the tangent turns 90° or more within one edge \
                         (repeated points or a cusp); sample the spine more finely",
                        k + 1
                    ),
                ));
            }
            if r[k].dot(r[k + 1]) <= -0.5 {
                return Err(InputError::new(
                    arg,
                    format!("rows {k} and {}: the frame rolls too fast", k + 1),
                ));
            }
        }
        let kv = curvatures(call, points, &t, closed, cancel)?;
        let mut m = alloc::with_capacity(call, n - 1)?;
        let mut pc = alloc::with_capacity(call, n - 1)?;
        for k in 0..n - 1 {
            cancel::poll(k, cancel)?;
            let e = points[k + 1] - points[k];
            let h = e.length();
            let pos = Hermite::new(points[k], points[k + 1], h * t[k], h * t[k + 1]).power();
            // slopes h κ_j: the model's curvature (dt/da)/σ is κ_j at the samples (σ = h)
            let coef = Hermite::new(t[k], t[k + 1], h * kv[k], h * kv[k + 1]).power();
            for i in 0..=8 {
                let a = i as f64 / 8.0;
                let sigma = pos.d1(a).dot(coef.value(a));
                if !(sigma > 0.0) || !kv[k].is_finite() {
                    return Err(InputError::new(
                        arg,
                        format!(
                            "rows {k} and {}: the spine turns too fast between samples; \
                             sample it more finely",
                            k + 1
                        ),
                    ));
                }
            }
            m.push(coef);
            pc.push(pos);
        }
        let rb = alloc::try_collect(
            call,
            (0..n - 1).map(|k| {
                cancel::poll(k, cancel)?;
                Ok(minimal_rotate(t[k + 1], t[k], r[k + 1]))
            }),
            &cancel::never,
        )?;
        Ok(SpineModel {
            scale: to_model,
            c: pts,
            t,
            r,
            m,
            p: pc,
            rb,
            closed,
        })
    }

    pub fn len(&self) -> usize {
        self.c.len()
    }

    pub fn is_empty(&self) -> bool {
        self.c.is_empty()
    }

    /// The unnormalised tangent `m(a)` of edge `k`.
    #[inline]
    pub fn m_at(&self, k: usize, a: f64) -> DVec3 {
        self.m[k].value(a)
    }

    /// The position `C(a)` on edge `k`.
    #[inline]
    pub fn c_at(&self, k: usize, a: f64) -> DVec3 {
        self.p[k].value(a)
    }

    /// The model at edge `k`, `a ∈ [0, 1]`.
    #[inline]
    pub fn eval(&self, k: usize, a: f64) -> Local {
        self.eval_lanes(&[k], &[a])[0]
    }

    /// [`SpineModel::eval`] of `L` points at once, stage by stage across the lanes: the chains
    /// of square roots and divisions of different points are independent, so the processor
    /// overlaps them (one point alone waits on each in turn).
    #[inline(always)]
    pub fn eval_lanes<const L: usize>(&self, k: &[usize; L], a: &[f64; L]) -> [Local; L] {
        // r_k and r_{k+1} (carried back to t_k) blended in the normal plane of t_k, then
        // carried to t(a) by the minimal rotation: r_k at a = 0, r_{k+1} at a = 1, and
        // equivariant under a common roll of the frames (so swapping spines inverts the map).
        // The rotation keeps lengths, so the blend is normalised by its length before it.
        let mut q = [DVec3::ZERO; L];
        let mut e = [DVec3::ZERO; L];
        let mut m = [DVec3::ZERO; L];
        let mut dt = [DVec3::ZERO; L];
        let mut w = [DVec3::ZERO; L];
        for l in 0..L {
            let (p, c) = (&self.p[k[l]], &self.m[k[l]]);
            q[l] = p.value(a[l]);
            e[l] = p.d1(a[l]);
            m[l] = c.value(a[l]);
            dt[l] = c.d1(a[l]);
            let r0 = self.r[k[l]];
            w[l] = r0 + a[l] * (self.rb[k[l]] - r0);
        }
        let mut inv_ml = [0.0; L];
        let mut inv_w = [0.0; L];
        for l in 0..L {
            inv_ml[l] = 1.0 / m[l].length();
            inv_w[l] = 1.0 / w[l].length();
        }
        let mut out = [Local {
            q: DVec3::ZERO,
            t: DVec3::ZERO,
            u: DVec3::ZERO,
            v: DVec3::ZERO,
            sigma: 0.0,
            kappa: DVec2::ZERO,
        }; L];
        let mut ta = [DVec3::ZERO; L];
        for l in 0..L {
            let t = m[l] * inv_ml[l];
            ta[l] = (dt[l] - t * t.dot(dt[l])) * inv_ml[l];
            out[l].q = q[l];
            out[l].t = t;
            out[l].sigma = e[l].dot(t);
        }
        for l in 0..L {
            let t = out[l].t;
            let um = minimal_rotate(self.t[k[l]], t, w[l]) * inv_w[l];
            let u = um - t * t.dot(um);
            let v = t.cross(u);
            let kv = ta[l] * (1.0 / out[l].sigma);
            out[l].u = u;
            out[l].v = v;
            out[l].kappa = DVec2::new(kv.dot(u), kv.dot(v));
        }
        out
    }
}

/// Compass walk (Zhuo's thesis, the discrete stretch of the posed spine): points on the
/// polyline `posed`, from its first point, whose consecutive distances are `chords` (so every
/// edge keeps its rest length); past the end of the polyline, along its last edge. `posed`
/// needs ≥ 2 distinct consecutive points and the chords must be positive (errors name
/// `posed_spine` and `rest_spine`, whose chords they are).
pub fn compass_walk(posed: &[DVec3], chords: &[f64]) -> crate::error::Result<Vec<DVec3>> {
    check_walk(posed, chords)?;
    scaled_walk(posed, chords, &mut Vec::new(), &cancel::never)
}

/// The input checks of [`compass_walk`].
fn check_walk(posed: &[DVec3], chords: &[f64]) -> crate::error::Result<()> {
    use crate::error::InputError;
    if posed.len() < 2 {
        return Err(InputError::new(
            "posed_spine",
            format!("need at least 2 points, got {}", posed.len()),
        ));
    }
    if let Some(i) = chords.iter().position(|h| !(h.is_finite() && *h > 0.0)) {
        return Err(InputError::new(
            "rest_spine",
            format!("chord {i} is not positive and finite"),
        ));
    }
    Ok(())
}

/// [`compass_walk`], with the polyline position `k + u` of every point (on edge `k` of
/// `posed` at the fraction `u`; `u > 1` past the end, along the last edge). Polls `cancel`
/// every [`cancel::BLOCK`] steps of the walk and fails with [`InputError::stopped`] once it
/// says stop.
pub fn compass_walk_located(
    posed: &[DVec3],
    chords: &[f64],
    cancel: Cancel<'_>,
) -> crate::error::Result<(Vec<DVec3>, Vec<f64>)> {
    check_walk(posed, chords)?;
    let mut at = alloc::with_capacity("SpineBinding.deform", chords.len() + 1)?;
    let pts = scaled_walk(posed, chords, &mut at, cancel)?;
    Ok((pts, at))
}

/// The walk on checked input, on a spine far from unit size divided by its power-of-two
/// scale first (exact; the walk squares chords twice, |e·(a − c)|²) and multiplied back;
/// pushes the polyline positions onto `at` when it is given with capacity.
fn scaled_walk(
    posed: &[DVec3],
    chords: &[f64],
    at: &mut Vec<f64>,
    cancel: Cancel<'_>,
) -> crate::error::Result<Vec<DVec3>> {
    use crate::error::InputError;
    let (lo, hi) = crate::frames::geometry::bounds(posed);
    let out = match crate::math::scale::curve_exponent(lo, hi) {
        None => walk(posed, chords, at, cancel)?,
        Some(k) => {
            let p = scale::try_scaled("SpineBinding.deform", posed, k)?;
            let h = alloc::collect(
                "SpineBinding.deform",
                chords.iter().map(|&c| scale::ldexp(c, k)),
            )?;
            scale::try_scaled("SpineBinding.deform", &walk(&p, &h, at, cancel)?, -k)?
        }
    };
    if let Some(i) = out.windows(2).position(|w| w[0] == w[1]) {
        return Err(InputError::new(
            "posed_spine",
            format!(
                "resampled to the rest spine's chords ({:e} at chord {i}), samples {i} and {} \
                 fall on the same float64 point at coordinates of size {:e}: the rest spine's \
                 chords are out of the representable range at the posed spine's size; pose a \
                 spine of the rest spine's size, or pass stretchable=True",
                chords[i],
                i + 1,
                crate::math::scale::max_abs(out[i])
            ),
        ));
    }
    Ok(out)
}

/// The walk; pushes the polyline positions onto `at` when it is given with capacity.
fn walk(
    posed: &[DVec3],
    chords: &[f64],
    at: &mut Vec<f64>,
    cancel: Cancel<'_>,
) -> Result<Vec<DVec3>> {
    let record = at.capacity() > 0;
    let mut out = alloc::with_capacity("SpineBinding.deform", chords.len() + 1)?;
    let mut c = posed[0];
    out.push(c);
    if record {
        at.push(0.0);
    }
    let last = posed.len() - 2;
    let mut seg = 0;
    // steps taken (chords and edges passed), for the polls
    let mut steps = 0usize;
    for &h in chords {
        let next = loop {
            cancel::poll(steps, cancel)?;
            steps += 1;
            let (a, b) = (posed[seg], posed[seg + 1]);
            let e = b - a;
            // |a + t e − c|² = h², the larger root (ahead of c)
            let (ee, ec) = (e.dot(e), e.dot(a - c));
            let cc = (a - c).length_squared() - h * h;
            let disc = (ec * ec - ee * cc).max(0.0);
            let t = (-ec + disc.sqrt()) / ee;
            if t <= 1.0 || seg == last {
                if record {
                    at.push(seg as f64 + t);
                }
                break a + t * e;
            }
            seg += 1;
        };
        out.push(next);
        c = next;
    }
    Ok(out)
}
