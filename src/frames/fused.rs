//! The fused fast path of the most common calls: frames of one open curve by double
//! reflection or the rotation method, from its points alone (with the five-point
//! chord-length tangents) or from its points and given tangents.
//!
//! The general driver ([`super::compute_general`]) makes one pass per stage over the whole
//! curve: finite check, chord lengths, tangents (a fresh `(n, 3)` buffer), alignment check,
//! then the transport scan. On long curves these passes and the page faults of the fresh
//! buffers cost more than the transport itself. Here every chunk of the parallel scan
//! works through its samples in blocks of [`BLOCK`]: chord lengths and unit tangents of the
//! block go into small buffers that stay in cache, the checks run on them, and the frames are
//! written at once. The arithmetic is that of the general path: the same formulas, written
//! for four samples at a time ([`super::lanes`]) with the same IEEE operations in the same
//! order, on the same chunks, so the frames are bit-identical; tests compare the two.
//!
//! Errors are never reported from here: where any check fails (a NaN, a repeated point, a
//! cusp, a segment against its tangents, a bad `initial`/`end`) this returns `None` and the
//! caller runs the general path, which names the argument and the row.

use glam::DVec3;
use rayon::prelude::*;

use super::double_reflection::dr_step;
use super::geometry::{any_perpendicular, bounds, rotate_about, signed_angle};
use super::lanes::{Arith, F4, L, V4};
use super::rotation::rotation_step;
use super::tangent_lanes::{CHORD_MARGIN, CORNER_COS2, OVERSHOOT_COS, centred_weights};
use super::tangents::{circle_normal, five_point_unit_open};
use super::transport::{ChunkEnds, Scan, Twist, plan, write_frame};
use super::validate::{MIN_ALIGNMENT, REPEAT_REL, repeated};
use super::{Method, Request, STRAIGHT_TOL, TangentRule, resolve};
use crate::math::rotation::minimal_rotate_with;

/// Samples per block: chords and tangents of a block stay in the L1/L2 cache.
pub const BLOCK: usize = 1024;

/// Samples searched serially for the first bend (the default initial vector) before the
/// search goes parallel.
const SERIAL_SEARCH: usize = 256;

/// `v̂·(t_i + t_{i+1}) > MIN_ALIGNMENT`, as `validate::aligned` tests it.
#[inline(always)]
fn aligned(v: DVec3, ti: DVec3, tj: DVec3) -> bool {
    aligned_with(v, v.length_squared(), ti, tj)
}

#[inline(always)]
fn aligned_with(v: DVec3, vv: f64, ti: DVec3, tj: DVec3) -> bool {
    let d = v.dot(ti + tj);
    d > 0.0 && d * d > MIN_ALIGNMENT * MIN_ALIGNMENT * vv
}

/// Frames of an open curve given by points, with or without tangents (double reflection or
/// the rotation method; five-point tangents when none are given; `n ≥ 5`), or `None` when
/// the request is of another kind or any check fails.
// Kept whole: the closures `tan`, `step` and `normal` (tangents estimated on the fly) serve
// the checks, the initial-vector search, the end twist and the chunked scan alike.
pub(super) fn try_open_points(
    req: &Request,
    out: &mut [f64],
    cancel: crate::run::cancel::Cancel<'_>,
) -> Option<f64> {
    let x = req.points?;
    let n = x.len();
    let given = req.tangents;
    if given.is_some_and(|t| t.len() != n)
        || req.analytic.is_some()
        || req.closed
        || !matches!(req.method, Method::DoubleReflection | Method::Rotation)
        || req.tangent_chords
        || (given.is_none() && req.tangent_rule != TangentRule::FivePointBounded)
        || n < 5
        || out.len() != 9 * n
    {
        return None;
    }
    let h = |j: usize| (x[j + 1] - x[j]).length();
    let tan = |i: usize| match given {
        Some(t) => unit(t[i]),
        None => five_point_unit_open(x, i, h),
    };
    let rotation = req.method == Method::Rotation;
    // the method's step i → i + 1 (`DoubleReflection::step`, `Rotation::step`)
    let step = move |i: usize, ti: DVec3, tj: DVec3, r: DVec3| {
        if rotation {
            rotation_step(ti, tj, r)
        } else {
            dr_step(x[i + 1] - x[i], ti, tj, r)
        }
    };

    // The default initial vector: the principal normal at the first sample where the curve
    // bends, carried back to sample 0 (as `Ctx::run`).
    let (lo, hi) = bounds(x);
    let (scale, diag) = (lo.abs().max(hi.abs()).max_element(), (hi - lo).length());
    if !(scale.is_finite() && diag.is_finite()) {
        return None;
    }
    let noise = 64.0 * f64::EPSILON * scale;
    // chords longer than this are not repeated points: `repeated` needs
    // |b − a|_∞ ≤ floor, and |b − a|_∞ ≥ |b − a|/√3 (with a margin for the rounding of the
    // computed length)
    let apart = 4.0 * crate::math::scale::half_extent(lo, hi) * REPEAT_REL;
    let normal = |i: usize, ti: DVec3| {
        circle_normal(x, ti, i, false, noise)
            .and_then(|(nrm, kappa)| (kappa * diag > STRAIGHT_TOL).then_some(nrm))
    };
    let t0 = tan(0)?;
    let r0 = match &req.initial {
        Some(o) => resolve(o, t0, 0, "initial").ok()?,
        None => {
            let p = any_perpendicular(t0);
            let lim = n.min(SERIAL_SEARCH);
            let mut found = None;
            for i in 0..lim {
                if let Some(v) = normal(i, tan(i)?) {
                    found = Some((i, v));
                    break;
                }
            }
            if found.is_none() && lim < n {
                found = (lim..n).into_par_iter().find_map_first(|i| {
                    if cancel() {
                        return Some((0, p));
                    }
                    tan(i).and_then(|ti| normal(i, ti)).map(|v| (i, v))
                });
            }
            if cancel() {
                return None;
            }
            match found {
                None => p,
                Some((k, nk)) => {
                    let (mut r, mut ti) = (p, t0);
                    for i in 0..k {
                        let tj = tan(i + 1)?;
                        r = step(i, ti, tj, r);
                        ti = tj;
                    }
                    rotate_about(p, t0, signed_angle(r, nk, ti))
                }
            }
        }
    };
    let twist = match &req.end {
        Some(o) => Twist::End {
            target: resolve(o, tan(n - 1)?, n - 1, "end").ok()?,
            turns: req.turns,
        },
        None => Twist::None,
    };

    // The scan, its chunks fused with the chords, tangents and checks. A chunk's checks cover
    // the segments inside it; the one that leads into it is checked here.
    let (_, cs) = plan(n, true);
    let work = |c: usize, start: Option<DVec3>, buf: &mut [f64]| {
        if cancel() {
            return None;
        }
        let a = c * cs;
        if a > 0 && !aligned(x[a] - x[a - 1], tan(a - 1)?, tan(a)?) {
            return None;
        }
        let job = Job {
            x,
            given,
            rotation,
            apart,
            a,
            b: (a + cs).min(n),
            start,
        };
        chunk(job, buf)
    };
    // every tangent the scan asks for has passed its chunk's checks by then
    let tt = |i: usize| tan(i).unwrap_or(DVec3::ZERO);
    Scan {
        boundary_step: |i: usize, r: DVec3| step(i, tt(i), tt(i + 1), r),
        tangent: tt,
        seg: |i: usize| h(i.min(n - 2)),
        n,
        closed: false,
        r0,
        twist,
        cs,
        ext: n,
    }
    .scan(work, out, cancel)
}

/// A given tangent made unit, as `tangents::normalize_all` does; `None` where it cannot be.
#[inline(always)]
fn unit(v: DVec3) -> Option<DVec3> {
    crate::math::scale::normalize(v)
}

/// The given tangents `s … te − 1` made unit into `t` (four at a time), or `None` where one
/// cannot be.
#[inline(always)]
fn given_tangents(tg: &[DVec3], s: usize, te: usize, t: &mut [&mut [f64]; 3]) -> Option<()> {
    let mut bad = 0u32;
    let mut i = s;
    while i + L <= te {
        let g = &tg[i..i + L];
        let v = V4 {
            x: F4([g[0].x, g[1].x, g[2].x, g[3].x]),
            y: F4([g[0].y, g[1].y, g[2].y, g[3].y]),
            z: F4([g[0].z, g[1].z, g[2].z, g[3].z]),
        };
        let l = v.dot(v).sqrt();
        let u = V4 {
            x: v.x / l,
            y: v.y / l,
            z: v.z / l,
        };
        let finite = l.mask(l, |p, q| (p - q) == 0.0);
        bad |= !(l.mask(F4::splat(0.0), |p, q| p > q) & finite & u.finite_mask()) & 0b1111;
        u.store(&mut muts(t), i - s);
        i += L;
    }
    for (j, &v) in tg.iter().enumerate().take(te).skip(i) {
        set(t, j - s, unit(v)?);
    }
    (bad == 0).then_some(())
}

/// Per-block scratch arrays, one value per sample or chord (structure of arrays, so that
/// four samples go through each operation together, see [`super::lanes`]). Each has room
/// for a block, its stencil margins and the padding of the last group of lanes; the padded
/// lanes compute garbage that nothing reads.
struct Scratch<'s> {
    /// Points `x_lo …`.
    p: [&'s mut [f64]; 3],
    /// Chords `c_j = x_{j+1} − x_j`, their squares `q_j = c_j·c_j` and lengths `h_j = √q_j`.
    c: [&'s mut [f64]; 3],
    q: &'s mut [f64],
    h: &'s mut [f64],
    /// Unit tangents `t_s …` of the block (and one past it).
    t: [&'s mut [f64]; 3],
    /// The curve-only vectors of the double-reflection step `i → i + 1`
    /// ([`super::double_reflection::dr_step_with`]): `r′ = r − (c_i·r) a_i − (v2_i·r) b_i`.
    a: [&'s mut [f64]; 3],
    v2: [&'s mut [f64]; 3],
    b: [&'s mut [f64]; 3],
    /// The rotation method's step instead: axis `t_i × t_{i+1}` (in `a`), its cosine
    /// `t_i·t_{i+1}` and `1 + cos` ([`rotation_step`]).
    cos: &'s mut [f64],
    den: &'s mut [f64],
    /// The transported reference vectors `r_s …` of the block.
    r: [&'s mut [f64]; 3],
}

/// Room beyond a block's samples: stencil margins (2 + 2, one tangent past the block) and
/// the padding of the last group of lanes.
const MARGIN: usize = 16;

impl<'s> Scratch<'s> {
    /// The arrays for blocks of up to `block` samples (short curves of a bundle need little),
    /// cut from one allocation `store`.
    fn new(store: &'s mut Vec<f64>, block: usize) -> Self {
        let room = block + MARGIN;
        store.clear();
        // `block` ≤ [`BLOCK`]: a constant size per task, not the input's
        store.resize(25 * room, 0.0);
        let mut rest: &'s mut [f64] = store;
        let mut v = || {
            let (head, tail) = std::mem::take(&mut rest).split_at_mut(room);
            rest = tail;
            head
        };
        Scratch {
            p: [v(), v(), v()],
            c: [v(), v(), v()],
            q: v(),
            h: v(),
            t: [v(), v(), v()],
            a: [v(), v(), v()],
            v2: [v(), v(), v()],
            b: [v(), v(), v()],
            cos: v(),
            den: v(),
            r: [v(), v(), v()],
        }
    }
}

#[inline(always)]
fn refs<'a>(v: &'a [&mut [f64]; 3]) -> [&'a [f64]; 3] {
    [&*v[0], &*v[1], &*v[2]]
}

#[inline(always)]
fn muts<'a>(v: &'a mut [&mut [f64]; 3]) -> [&'a mut [f64]; 3] {
    let [x, y, z] = v;
    [&mut **x, &mut **y, &mut **z]
}

#[inline(always)]
fn get(v: &[&[f64]; 3], k: usize) -> DVec3 {
    DVec3::new(v[0][k], v[1][k], v[2][k])
}

#[inline(always)]
fn set(v: &mut [&mut [f64]; 3], k: usize, w: DVec3) {
    v[0][k] = w.x;
    v[1][k] = w.y;
    v[2][k] = w.z;
}

/// The lanes of the group starting at `g` that lie before `end`.
#[inline(always)]
fn live(g: usize, end: usize) -> u32 {
    if end - g >= L {
        (1 << L) - 1
    } else {
        (1 << (end - g)) - 1
    }
}

/// One chunk's share of the scan: rows `a..b` of the curve `x` (with its `given` tangents,
/// if any), transported from `start`; chords longer than `apart` cannot be repeated points.
#[derive(Clone, Copy)]
struct Job<'a> {
    x: &'a [DVec3],
    given: Option<&'a [DVec3]>,
    /// The rotation method's step instead of double reflection's.
    rotation: bool,
    apart: f64,
    a: usize,
    b: usize,
    start: Option<DVec3>,
}

/// Rows `a..b` of the scan: transport from `start` (a provisional vector ⟂ `t_a` when
/// `None`), writing the frames into `buf`; `None` if a check fails in the chunk.
///
/// On x86-64 processors with AVX2 the same code is compiled a second time for 256-bit
/// vectors (four lanes of [`F4`] in one instruction instead of two) and chosen at run time.
/// Measured on this project's 2-core machine (a Rust timing loop over 1M helix points into a
/// paged-in buffer, best of 30): 46–51 → 39–40 ms on one thread, 27–35 → 24–26 ms on two.
/// The operations are the same IEEE operations (Rust never fuses a multiply and an add on
/// its own), so both versions give the same bits (a unit test compares them).
fn chunk(job: Job, buf: &mut [f64]) -> Option<ChunkEnds> {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: `chunk_avx2` only needs the processor to support AVX2, checked just above.
        return unsafe { chunk_avx2(job, buf) };
    }
    chunk_body(job, buf)
}

/// [`chunk_body`] compiled for AVX2. Safety: call only where AVX2 is available.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn chunk_avx2(job: Job, buf: &mut [f64]) -> Option<ChunkEnds> {
    chunk_body(job, buf)
}

/// The work of [`chunk`].
///
/// Per block of samples the points are copied into coordinate arrays ([`load_points`]); one
/// loop computes the chords ([`block_chords`]), one the interior tangents
/// ([`estimated_tangents`]), one the curve-only vectors of every step ([`step_vectors`]: of
/// double reflection, or the axis and cosine of the rotation method), each four samples at a
/// time and free of dependencies between samples; only the transport loop
/// ([`transport_rotation`], [`transport_reflection`]) carries `r` from sample to sample.
/// Every value comes from the operations of the scalar functions that the general path
/// calls, in the same order, so the frames are the same bit for bit. The steps are
/// `#[inline(always)]`, so that the AVX2 build compiles them for AVX2 too.
#[inline(always)]
fn chunk_body(job: Job, buf: &mut [f64]) -> Option<ChunkEnds> {
    let Job {
        x,
        given,
        rotation,
        apart,
        a,
        b,
        start,
    } = job;
    let n = x.len();
    let mut store = Vec::new();
    let mut w = Scratch::new(&mut store, BLOCK.min(b - a));
    let mut rows = buf.chunks_exact_mut(9);
    let (mut s0, mut r, mut len) = (DVec3::ZERO, DVec3::ZERO, 0.0);
    let mut s = a;
    while s < b {
        let blk = Block::new(s, b, n);
        load_points(&mut w, x, &blk);
        block_chords(&mut w, &blk);
        if repeated_point(&w, x, &blk, apart) {
            return None;
        }
        match given {
            Some(tg) => given_tangents(tg, s, blk.te, &mut w.t)?,
            None => estimated_tangents(&mut w, x, &blk)?,
        }
        // the steps i → i + 1 inside the chunk
        let steps = blk.e.min(b - 1).saturating_sub(s);
        if !step_vectors(&mut w, &blk, steps, rotation) {
            return None;
        }
        if s == a {
            r = start.unwrap_or_else(|| any_perpendicular(get(&refs(&w.t), 0)));
            s0 = r;
        }
        r = if rotation {
            transport_rotation(&mut w, steps, r)
        } else {
            transport_reflection(&mut w, s - blk.lo, steps, r)
        };
        let cnt = blk.e - s;
        if steps < cnt {
            // the chunk's last row (no step leaves it inside the chunk)
            set(&mut w.r, steps, r);
        }
        // the rows, and the chunk's length (`h_j` summed in order, as the general path)
        for (m, f) in (0..cnt).zip(rows.by_ref()) {
            write_frame(f, get(&refs(&w.r), m), get(&refs(&w.t), m));
        }
        len = w.h[s - blk.lo..blk.e.min(n - 1) - blk.lo]
            .iter()
            .fold(len, |acc, &h| acc + h);
        s = blk.e;
    }
    Some((s0, r, len))
}

/// A block of a chunk: samples `s … e − 1`, their tangents `s … te − 1` (one past the block
/// for its last step), the points of those tangents' stencils `lo … pe − 1` (the scratch
/// arrays start at `lo`) and the chords `j ∈ [lo, hi)`.
#[derive(Clone, Copy)]
struct Block {
    s: usize,
    e: usize,
    te: usize,
    lo: usize,
    pe: usize,
    hi: usize,
}

impl Block {
    /// The block starting at sample `s` of a chunk ending before `b`, on a curve of `n`.
    #[inline(always)]
    fn new(s: usize, b: usize, n: usize) -> Self {
        let e = (s + BLOCK).min(b);
        let te = if e < b { e + 1 } else { e };
        let pe = (te + 2).min(n);
        Block {
            s,
            e,
            te,
            lo: s.saturating_sub(2),
            pe,
            hi: pe - 1,
        }
    }
}

/// The block's points into the coordinate arrays.
#[inline(always)]
fn load_points(w: &mut Scratch, x: &[DVec3], blk: &Block) {
    for (k, xk) in x[blk.lo..blk.pe].iter().enumerate() {
        w.p[0][k] = xk.x;
        w.p[1][k] = xk.y;
        w.p[2][k] = xk.z;
    }
}

/// Chords, their squares and lengths: `length()` is `dot(self).sqrt()`; the square is kept
/// for the checks and steps.
#[inline(always)]
fn block_chords(w: &mut Scratch, blk: &Block) {
    let p = refs(&w.p);
    let mut c = muts(&mut w.c);
    for k in (0..blk.hi - blk.lo).step_by(L) {
        let ck = V4::load(&p, k + 1) - V4::load(&p, k);
        let qk = ck.dot(ck);
        ck.store(&mut c, k);
        qk.store(w.q, k);
        qk.sqrt().store(w.h, k);
    }
}

/// Does the block hold a repeated point (`validate::repeated`, floor `apart / 2`)?
///
/// `|b − a|_∞ ≥ h/√3`, so a chord longer than `apart` cannot coincide (the exact test runs
/// only on the rare short ones). Non-finite samples need no test of their own: ±inf anywhere
/// already failed the bounding-box scale; a NaN at sample i enters its own tangent's stencil
/// (every term is a difference with x_i), or, with given tangents, the chords next to it, so
/// the tangent or the alignment check of those steps refuses the block.
#[inline(always)]
fn repeated_point(w: &Scratch, x: &[DVec3], blk: &Block, apart: f64) -> bool {
    let (s, lo, n) = (blk.s, blk.lo, x.len());
    let (j0, j1) = (s - lo, blk.e.min(n - 1) - lo);
    w.h[j0..j1]
        .iter()
        .fold(false, |acc, &hj| acc | (hj <= apart))
        && (s..blk.e.min(n - 1))
            .any(|j| w.h[j - lo] <= apart && repeated(x[j], x[j + 1], 0.5 * apart))
}

/// The five-point tangents of the block (`five_point_unit_open`): the interior ones
/// (`i ≥ 2`, `i + 2 < n`) four at a time, the scalar function where a group fails its checks
/// and at the samples next to the ends; `None` where one cannot be estimated.
#[inline(always)]
fn estimated_tangents(w: &mut Scratch, x: &[DVec3], blk: &Block) -> Option<()> {
    let (s, te, lo, hi, n) = (blk.s, blk.te, blk.lo, blk.hi, x.len());
    let (i0, i1) = (s.max(2), te.min(n.saturating_sub(2)).max(s.max(2)));
    if interior_tangents(w, blk, i0, i1) != 0 {
        // a cusp, a non-finite value or an overshoot: the scalar function decides
        let h = |j: usize| w.h[j - lo];
        for i in i0..i1 {
            let t = five_point_unit_open(x, i, h)?;
            set(&mut w.t, i - s, t);
        }
    }
    // the samples next to the ends: one-sided stencils
    for i in (s..te).filter(|&i| i < i0 || i >= i1) {
        let h = |j: usize| {
            if j >= lo && j < hi {
                w.h[j - lo]
            } else {
                (x[j + 1] - x[j]).length()
            }
        };
        let t = five_point_unit_open(x, i, h)?;
        set(&mut w.t, i - s, t);
    }
    Some(())
}

/// The centred five-point tangents `i0 … i1 − 1`, four at a time, with the checks of
/// `five_point_unit_open` (a positive finite length, no overshoot against the circle
/// estimate); returns the mask of the lanes that failed them.
#[inline(always)]
fn interior_tangents(w: &mut Scratch, blk: &Block, i0: usize, i1: usize) -> u32 {
    let (s, lo) = (blk.s, blk.lo);
    let guard2 = F4::splat(OVERSHOOT_COS * OVERSHOOT_COS);
    let margin2 = F4::splat(CHORD_MARGIN * CHORD_MARGIN);
    let corner2 = F4::splat(CORNER_COS2);
    let zero = F4::splat(0.0);
    let mut bad = 0u32;
    let (p, c) = (refs(&w.p), refs(&w.c));
    let (q, h) = (&w.q[..], &w.h[..]);
    let mut t = muts(&mut w.t);
    for g in (i0..i1).step_by(L) {
        let k = g - lo;
        let wt = centred_weights(
            F4::load(h, k - 2),
            F4::load(h, k - 1),
            F4::load(h, k),
            F4::load(h, k + 1),
        );
        let pc = V4::load(&p, k);
        let v = (V4::load(&p, k - 2) - pc).scale(wt[0])
            + (V4::load(&p, k - 1) - pc).scale(wt[1])
            + (V4::load(&p, k + 1) - pc).scale(wt[2])
            + (V4::load(&p, k + 2) - pc).scale(wt[3]);
        let l = v.dot(v).sqrt();
        let u = v.scale(F4::splat(1.0) / l);
        // the circle estimate (`circle_raw`): |c_i|² c_{i−1} + |c_{i−1}|² c_i
        let cw =
            V4::load(&c, k - 1).scale(F4::load(q, k)) + V4::load(&c, k).scale(F4::load(q, k - 1));
        let d = u.dot(cw);
        // `guard_chords`' cheap test: a turn under 30°, within 60° of both chords (else the
        // scalar function makes its exact test and may turn the tangent towards the bisector)
        let (ci, co) = (V4::load(&c, k - 1), V4::load(&c, k));
        let (a, b) = (u.dot(ci), u.dot(co));
        let (qi, qo, turn) = (F4::load(q, k - 1), F4::load(q, k), ci.dot(co));
        let good = l.mask(zero, |p, q| p > q)
            & turn.mask(zero, |p, q| p >= q)
            & (turn * turn).mask(corner2 * (qi * qo), |p, q| p >= q)
            & u.finite_mask()
            & d.mask(zero, |p, q| p >= q)
            & (d * d).mask(guard2 * cw.dot(cw), |p, q| p >= q)
            & a.mask(zero, |p, q| p >= q)
            & b.mask(zero, |p, q| p >= q)
            & (a * a).mask(margin2 * qi, |p, q| p >= q)
            & (b * b).mask(margin2 * qo, |p, q| p >= q);
        bad |= !good & live(g, i1);
        u.store(&mut t, g - s);
    }
    bad
}

/// The curve-only part of the block's `steps` steps (`dr_step_with`: `a`, `v2`, `b`; or the
/// rotation method's axis, cosine and `1 + cos`) and their check (`aligned_with`); false
/// where a segment runs against its tangents.
#[inline(always)]
fn step_vectors(w: &mut Scratch, blk: &Block, steps: usize, rotation: bool) -> bool {
    let min2 = F4::splat(MIN_ALIGNMENT * MIN_ALIGNMENT);
    let (zero, two) = (F4::splat(0.0), F4::splat(2.0));
    let mut misaligned = 0u32;
    let (c, t) = (refs(&w.c), refs(&w.t));
    let q = &w.q[..];
    let (mut av, mut v2v, mut bv) = (muts(&mut w.a), muts(&mut w.v2), muts(&mut w.b));
    for m in (0..steps).step_by(L) {
        let k = m + blk.s - blk.lo;
        let (v1, vv) = (V4::load(&c, k), F4::load(q, k));
        let (ti, tj) = (V4::load(&t, m), V4::load(&t, m + 1));
        let d = v1.dot(ti + tj);
        let ok = d.mask(zero, |p, q| p > q) & (d * d).mask(min2 * vv, |p, q| p > q);
        misaligned |= !ok & live(m, steps);
        if rotation {
            let c = ti.dot(tj);
            ti.cross(tj).store(&mut av, m);
            c.store(w.cos, m);
            (F4::splat(1.0) + c).store(w.den, m);
            continue;
        }
        let k1 = two / vv;
        let tl = ti - v1.scale(k1 * v1.dot(ti));
        let v2 = tj - tl;
        let k2 = two / v2.dot(v2);
        (v1 - v2.scale(k2 * v2.dot(v1))).scale(k1).store(&mut av, m);
        v2.store(&mut v2v, m);
        v2.scale(k2).store(&mut bv, m);
    }
    misaligned == 0
}

/// The rotation method's transport of `r` over `steps` steps (`rotation_step`), keeping
/// each `r` before its step; returns the last one. The only loop that carries a value from
/// sample to sample, kept to the arithmetic of the step.
#[inline(always)]
fn transport_rotation(w: &mut Scratch, steps: usize, mut r: DVec3) -> DVec3 {
    let (ax, ay, az) = (&w.a[0][..steps], &w.a[1][..steps], &w.a[2][..steps]);
    let (cos, den) = (&w.cos[..steps], &w.den[..steps]);
    let [rx, ry, rz] = &mut w.r;
    let (rx, ry, rz) = (&mut rx[..steps], &mut ry[..steps], &mut rz[..steps]);
    for m in 0..steps {
        (rx[m], ry[m], rz[m]) = (r.x, r.y, r.z);
        let a = DVec3::new(ax[m], ay[m], az[m]);
        r = minimal_rotate_with(a, cos[m], den[m], r);
    }
    r
}

/// Double reflection's transport of `r` over `steps` steps (`dr_step_with`: `r′ = r −
/// (c_i·r) a_i − (v2_i·r) b_i`, the chords from scratch index `k0`), keeping each `r`
/// before its step; returns the last one.
#[inline(always)]
fn transport_reflection(w: &mut Scratch, k0: usize, steps: usize, mut r: DVec3) -> DVec3 {
    let (cx, cy, cz) = (
        &w.c[0][k0..k0 + steps],
        &w.c[1][k0..k0 + steps],
        &w.c[2][k0..k0 + steps],
    );
    let (ax, ay, az) = (&w.a[0][..steps], &w.a[1][..steps], &w.a[2][..steps]);
    let (vx, vy, vz) = (&w.v2[0][..steps], &w.v2[1][..steps], &w.v2[2][..steps]);
    let (bx, by, bz) = (&w.b[0][..steps], &w.b[1][..steps], &w.b[2][..steps]);
    let [rx, ry, rz] = &mut w.r;
    let (rx, ry, rz) = (&mut rx[..steps], &mut ry[..steps], &mut rz[..steps]);
    for m in 0..steps {
        (rx[m], ry[m], rz[m]) = (r.x, r.y, r.z);
        let v1 = DVec3::new(cx[m], cy[m], cz[m]);
        let (a, v2, b) = (
            DVec3::new(ax[m], ay[m], az[m]),
            DVec3::new(vx[m], vy[m], vz[m]),
            DVec3::new(bx[m], by[m], bz[m]),
        );
        r = r - v1.dot(r) * a - v2.dot(r) * b;
    }
    r
}

#[cfg(test)]
mod tests;
