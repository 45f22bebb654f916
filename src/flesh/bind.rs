//! Registration (Zhuo 2014 §1.1, Fig. 1, the registration step; Ch. VII "accurate projection").
//!
//! Each vertex is attached to the cross-section plane it lies in: on edge `k` the plane at
//! `a` passes through the interpolated position `C(a)` normal to the interpolated tangent
//! `m(a)` (both cubic in `a`, see [`super::spine`]), and `(P − C(a))·m(a) = 0` is solved to
//! full precision. Among the roots in `[0, 1]` of
//! every edge (and the straight extensions past both ends) the one closest to `P` wins — the
//! closest point of the polyline with the cross-sections turned smoothly from sample to
//! sample, so no vertex snaps to a sample (§7.1's "slicing") and the offset is exactly
//! normal to the interpolated tangent.
//!
//! Stored per vertex: `k` and [`COORDS`] numbers `[a, τ, α, β, σ0, σ0κα0, σ0κβ0]`: the edge
//! parameter, the tangential coordinate past an end (0 inside), the offset in the RMF
//! `(α, β)`, the rest spine's speed `σ0` and its curvature vector (RMF coordinates) at
//! `(k, a)` times `σ0`. Lengths are in the units of the input and the last two numbers have
//! none, so a binding does not depend on the normalisation of the rest spine's model (see
//! [`SpineModel`]) and any posed spine's model can read it.

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::section::{MAX_LANES, edge_roots, edge_roots_lanes};
use super::spine::SpineModel;
use crate::error::Result;
use crate::math::bvh::Aabb;
use crate::math::chain::ChainBoxes;
use crate::run::alloc;
use crate::run::cancel::Cancel;

/// Numbers stored per vertex besides the edge index.
pub const COORDS: usize = 7;

/// The registration of many vertices on one rest spine.
#[derive(Clone, Debug)]
pub struct Binding {
    pub edge: Vec<i64>,
    pub coords: Vec<f64>,
}

/// The rest spine's edges in a hierarchy of boxes ([`ChainBoxes`]). Edge `k`'s curve is
/// `C(a) = C_k + a E_k + h (h10(a) d_k + h11(a) d_{k+1})` (the Hermite form with slopes
/// `h t`, `h = |E_k|`, `d_j = t_j − E_k/h`, since `h01 + h10 + h11 = a`), so it stays within
/// `ρ_k = (4/27) h (|d_k| + |d_{k+1}|)` of its chord (`|h10|, |h11| ≤ 4/27` on `[0, 1]`):
/// the distance from `P` to the chord minus `ρ_k` bounds the distance to the curve from
/// below. The boxes are the chords' widened by `ρ_k`; they hold both samples.
struct Edges {
    tree: ChainBoxes,
    /// `ρ_k`, slightly enlarged against round-off.
    reach: Vec<f64>,
}

/// Relative margin on squared distances from boxes: a box nearer than the best answer by
/// less than this may still hold it once both are rounded (kept, never pruned).
const BOX_MARGIN: f64 = 1e-9;

impl Edges {
    fn new(sp: &SpineModel) -> Result<Edges> {
        let n = sp.len();
        let reach: Vec<f64> = alloc::collect(
            "SpineBinding",
            (0..n - 1).map(|k| {
                let e = sp.c[k + 1] - sp.c[k];
                let h = e.length();
                let u = e / h;
                let rho = 4.0 / 27.0 * h * ((sp.t[k] - u).length() + (sp.t[k + 1] - u).length());
                // round-off of the curve's evaluation (power form about the origin) and of
                // this bound, relative to the coordinates' size, not only the edge's
                let size = sp.c[k].abs().max_element() + sp.c[k + 1].abs().max_element() + h;
                rho * (1.0 + 1e-9) + 1e-12 * h + 64.0 * f64::EPSILON * size
            }),
        )?;
        let boxes: Vec<Aabb> = alloc::collect(
            "SpineBinding",
            (0..n - 1).map(|k| {
                let (a, b) = (sp.c[k], sp.c[k + 1]);
                let r = DVec3::splat(reach[k]);
                Aabb {
                    lo: a.min(b) - r,
                    hi: a.max(b) + r,
                }
            }),
        )?;
        Ok(Edges {
            tree: ChainBoxes::build(&boxes),
            reach,
        })
    }

    /// A lower bound of the squared distance from `p` to edge `k`'s curve.
    fn lower_bound(&self, sp: &SpineModel, k: usize, p: DVec3) -> f64 {
        let (a, e) = (sp.c[k], sp.c[k + 1] - sp.c[k]);
        let s = ((p - a).dot(e) / e.length_squared()).clamp(0.0, 1.0);
        // the round-off of the chord point and of the distance, relative to p's size
        let slack = 16.0 * f64::EPSILON * (p.abs().max_element() + a.abs().max_element());
        let lo = (p - (a + s * e)).length() - self.reach[k] - slack;
        // a margin for the round-off of the distances computed from the curve
        if lo > 0.0 {
            lo * lo * (1.0 - 1e-9)
        } else {
            0.0
        }
    }

    /// The sample nearest to `p` (the first of equally near ones), searched from edge
    /// `start` (the answer does not depend on it).
    fn nearest_sample(&self, sp: &SpineModel, p: DVec3, start: usize, stack: &mut Stack) -> usize {
        let mut best = (f64::INFINITY, 0);
        self.tree.nearest_from(p, start, best.0, stack, |k| {
            for j in [k, k + 1] {
                let d = (p - sp.c[j]).length_squared();
                if d < best.0 || (d == best.0 && j < best.1) {
                    best = (d, j);
                }
            }
            best.0 * (1.0 + BOX_MARGIN)
        });
        best.1
    }
}

/// Working state of a run of vertices: the edge of the vertex before (where the next one's
/// search starts) and the hierarchy's stack.
struct Scratch {
    hint: usize,
    stack: Stack,
}

/// The search stack of [`ChainBoxes::nearest_from`].
type Stack = Vec<(usize, usize, f64)>;

/// The best candidate of [`locate`] so far: squared distance, who (`-2` the start's
/// extension, `-1` the end's, `k ≥ 0` edge `k`, `i64::MIN` none yet), edge, `a`, `τ`.
#[derive(Clone, Copy)]
struct Best {
    d2: f64,
    who: i64,
    k: usize,
    a: f64,
    tau: f64,
}

/// The best candidate past the spine's ends: the straight extensions (a loop has none).
fn ends(sp: &SpineModel, p: DVec3) -> Best {
    let n = sp.len();
    let mut best = Best {
        d2: f64::INFINITY,
        who: i64::MIN,
        k: 0,
        a: 0.0,
        tau: 0.0,
    };
    let w = p - sp.c[0];
    let tau = w.dot(sp.t[0]);
    if tau < 0.0 && !sp.closed {
        best = Best {
            d2: (w - tau * sp.t[0]).length_squared(),
            who: -2,
            k: 0,
            a: 0.0,
            tau,
        };
    }
    let w = p - sp.c[n - 1];
    let tau = w.dot(sp.t[n - 1]);
    if tau > 0.0 && !sp.closed {
        let d2 = (w - tau * sp.t[n - 1]).length_squared();
        if d2 < best.d2 {
            best = Best {
                d2,
                who: -1,
                k: n - 2,
                a: 1.0,
                tau,
            };
        }
    }
    best
}

/// Register one vertex: `(k, a, τ)`. The closest point over the end extensions and every
/// edge's roots, the first found winning ties in the order: the start's extension, the
/// end's, the two edges at the sample nearest to `P`, then the other edges by index (the
/// nearest sample is searched only when two edges tie). The edge `s.hint` (the edge of the
/// vertex before, often the answer: consecutive vertices are often neighbours) is solved
/// first, then the others climbing the hierarchy of boxes from it, skipping those whose box
/// or ball lies farther than the best so far (`O(log n)` box tests for a vertex near the
/// hint's edge). The answer is the least candidate in that order whatever the hint.
#[cfg(test)]
fn locate(sp: &SpineModel, edges: &Edges, p: DVec3, s: &mut Scratch) -> (usize, f64, f64) {
    let hint = s.hint.min(sp.len() - 2);
    let roots = between_planes(sp, hint, p).then(|| edge_roots(sp, hint, p));
    locate_from(sp, edges, p, hint, roots.as_ref(), s)
}

/// Edge `k`'s roots for `p` (`roots` when they are known) as candidates against `best`
/// (see [`locate`]); `near` caches the sample nearest to `p` (searched with the stack
/// `inner` when two edges tie).
#[allow(clippy::too_many_arguments)]
fn consider(
    sp: &SpineModel,
    edges: &Edges,
    p: DVec3,
    k: usize,
    roots: Option<&[f64; 4]>,
    best: &mut Best,
    near: &mut Option<usize>,
    inner: &mut Stack,
) {
    let n = sp.len();
    // every point of the edge's curve is at least this far
    if edges.lower_bound(sp, k, p) > best.d2 {
        return;
    }
    let roots = match roots {
        Some(r) => *r,
        None => edge_roots(sp, k, p),
    };
    for a in roots {
        if !(-1e-12..=1.0 + 1e-12).contains(&a) {
            continue;
        }
        let a = a.clamp(0.0, 1.0);
        let d2 = (p - sp.c_at(k, a)).length_squared();
        let wins = d2 < best.d2
            || (d2 == best.d2 && best.who >= 0 && best.who != k as i64 && {
                // ranks: the edges at the nearest sample first, then by index
                let j = *near.get_or_insert_with(|| edges.nearest_sample(sp, p, k, inner));
                let (first, end) = (j.saturating_sub(1), (j + 1).min(n - 1));
                let rank = |k: usize| match (first..end).contains(&k) {
                    true => (k - first) as i64,
                    false => 2 + k as i64,
                };
                rank(k) < rank(best.who as usize)
            });
        if wins {
            *best = Best {
                d2,
                who: k as i64,
                k,
                a,
                tau: 0.0,
            };
        }
    }
}

/// [`locate`] with the roots `roots` of the hint edge `hint` given, or `None` when the hint
/// is not worth solving first (`p` outside its end planes). When the hint edge gives no
/// candidate, the two edges at the sample nearest to `p` are solved first instead and the
/// search climbs from there.
fn locate_from(
    sp: &SpineModel,
    edges: &Edges,
    p: DVec3,
    hint: usize,
    roots: Option<&[f64; 4]>,
    s: &mut Scratch,
) -> (usize, f64, f64) {
    let n = sp.len();
    let mut best = ends(sp, p);
    // the sample nearest to p, searched when first needed
    let mut near: Option<usize> = None;
    // the nearest sample's search stack (allocated when first used)
    let mut inner = Vec::new();
    // edges solved before the climb
    let mut done = [usize::MAX; 3];
    if let Some(r) = roots {
        consider(
            sp,
            edges,
            p,
            hint,
            Some(r),
            &mut best,
            &mut near,
            &mut inner,
        );
        done[0] = hint;
    }
    let start = if best.who == hint as i64 {
        hint
    } else {
        let j = *near.get_or_insert_with(|| edges.nearest_sample(sp, p, hint, &mut inner));
        let (first, end) = (j.saturating_sub(1), (j + 1).min(n - 1));
        // the one with the nearer chord first: a good bound prunes almost all others
        let mut two = [first, end - 1];
        if edges.lower_bound(sp, two[1], p) < edges.lower_bound(sp, two[0], p) {
            two.swap(0, 1);
        }
        for (i, &k) in two.iter().take(end - first).enumerate() {
            if !done.contains(&k) {
                consider(sp, edges, p, k, None, &mut best, &mut near, &mut inner);
                done[1 + i] = k;
            }
        }
        two[0]
    };
    let mut search = std::mem::take(&mut s.stack);
    edges
        .tree
        .nearest_from(p, start, best.d2 * (1.0 + BOX_MARGIN), &mut search, |k| {
            if !done.contains(&k) {
                consider(sp, edges, p, k, None, &mut best, &mut near, &mut inner);
            }
            best.d2 * (1.0 + BOX_MARGIN)
        });
    s.stack = search;
    if best.d2.is_infinite() {
        // cannot happen for finite input (the plane signs change somewhere); keep a
        // defined answer anyway: the nearest sample
        let near = near.unwrap_or_else(|| edges.nearest_sample(sp, p, hint, &mut inner));
        let (k, a) = if near + 1 < n {
            (near, 0.0)
        } else {
            (n - 2, 1.0)
        };
        return (k, a, 0.0);
    }
    s.hint = best.k;
    (best.k, best.a, best.tau)
}

/// Whether `p` lies between the end planes of edge `k` (where its section probably is:
/// then the hint is solved first).
fn between_planes(sp: &SpineModel, k: usize, p: DVec3) -> bool {
    (p - sp.c[k]).dot(sp.t[k]) >= 0.0 && (p - sp.c[k + 1]).dot(sp.t[k + 1]) <= 0.0
}

/// Register `vertices` on the rest spine.
///
/// Polls `cancel` before each vertex (see [`crate::run::cancel`]).
pub fn bind(rest: &SpineModel, vertices: &[DVec3], cancel: Cancel<'_>) -> Result<Binding> {
    super::check_vertices(vertices, rest.scale, "spine")?;
    let edges = Edges::new(rest)?;
    let nv = vertices.len();
    let mut edge = alloc::filled("SpineBinding", nv, 0i64)?;
    let mut coords = alloc::filled(
        "SpineBinding",
        alloc::product("SpineBinding", COORDS, nv, 8)?,
        0.0,
    )?;
    // blocks of consecutive vertices (often neighbours on the mesh): each vertex's search
    // starts from the edge of the vertex before
    edge.par_chunks_mut(BLOCK)
        .zip(coords.par_chunks_mut(COORDS * BLOCK))
        .zip(vertices.par_chunks(BLOCK))
        .for_each(|((eb, cb), vb)| {
            if cancel() {
                return;
            }
            let mut s = Scratch {
                hint: 0,
                stack: Vec::with_capacity(64),
            };
            bind_run(rest, &edges, vb, &mut s, eb, cb);
        });
    Ok(Binding { edge, coords })
}

/// Vertices per block of the registration (a Ctrl-C poll each).
const BLOCK: usize = 256;

/// Vertices registered together: the roots on their hint edge refined together (see
/// [`edge_roots_lanes`]), the spine evaluated at their sections together (see
/// [`SpineModel::eval_lanes`]).
const LANES: usize = MAX_LANES;

/// The bindings of a run of vertices (input units) into `e` and `c` (see the module notes):
/// `LANES` at a time, each search starting from the edge found for the vertex before them.
fn bind_run(
    rest: &SpineModel,
    edges: &Edges,
    vb: &[DVec3],
    s: &mut Scratch,
    eb: &mut [i64],
    cb: &mut [f64],
) {
    let mut i = 0;
    while i + LANES <= vb.len() {
        bind_lanes::<LANES>(
            rest,
            edges,
            &vb[i..],
            s,
            &mut eb[i..],
            &mut cb[COORDS * i..],
        );
        i += LANES;
    }
    while i < vb.len() {
        bind_lanes::<1>(
            rest,
            edges,
            &vb[i..],
            s,
            &mut eb[i..],
            &mut cb[COORDS * i..],
        );
        i += 1;
    }
}

/// The bindings of the first `L` vertices of `vb` (see [`bind_run`]).
#[inline(always)]
fn bind_lanes<const L: usize>(
    rest: &SpineModel,
    edges: &Edges,
    vb: &[DVec3],
    s: &mut Scratch,
    eb: &mut [i64],
    cb: &mut [f64],
) {
    let (to_model, to_input) = (rest.scale, rest.scale.inverse());
    let mut p = [DVec3::ZERO; L];
    for l in 0..L {
        p[l] = to_model.of3(vb[l]);
    }
    // the edge of the run's vertex before, for all L
    let hint = s.hint.min(rest.len() - 2);
    let mut inside = [false; L];
    for l in 0..L {
        inside[l] = between_planes(rest, hint, p[l]);
    }
    let roots = if inside.iter().all(|&b| b) {
        edge_roots_lanes(rest, &[hint; L], &p)
    } else {
        let mut r = [[f64::NAN; 4]; L];
        for l in 0..L {
            if inside[l] {
                r[l] = edge_roots(rest, hint, p[l]);
            }
        }
        r
    };
    let mut found = [(0usize, 0.0, 0.0); L];
    let (mut ks, mut as_) = ([0usize; L], [0.0; L]);
    for l in 0..L {
        let r = inside[l].then_some(&roots[l]);
        found[l] = locate_from(rest, edges, p[l], hint, r, s);
        (ks[l], as_[l]) = (found[l].0, found[l].1);
    }
    let loc = rest.eval_lanes(&ks, &as_);
    let len = |x: f64| to_input.of(x);
    for l in 0..L {
        let ((k, a, tau), l0) = (found[l], &loc[l]);
        let d = p[l] - l0.q - tau * l0.t;
        let sk = if tau != 0.0 {
            DVec2::ZERO
        } else {
            l0.kappa * l0.sigma
        };
        eb[l] = k as i64;
        cb[COORDS * l..COORDS * (l + 1)].copy_from_slice(&[
            a,
            len(tau),
            len(d.dot(l0.u)),
            len(d.dot(l0.v)),
            len(l0.sigma),
            sk.x,
            sk.y,
        ]);
    }
}

#[cfg(test)]
mod tests {
    use super::super::section::tests::model;
    use super::*;
    use crate::run::cancel;

    /// A circle of `n` samples as a loop (first row repeated), with its RMF (`r` the
    /// binormal z all along, which closes).
    fn circle(n: usize) -> (Vec<DVec3>, Vec<f64>) {
        let mut pts = Vec::new();
        let mut frames = Vec::new();
        for i in 0..=n {
            let a = std::f64::consts::TAU * (i % n) as f64 / n as f64;
            let (s, c) = a.sin_cos();
            pts.push(DVec3::new(c, s, 0.0));
            let (r, t) = (DVec3::Z, DVec3::new(-s, c, 0.0));
            let q = t.cross(r);
            // row-major (n, 3, 3), columns r, s, t
            frames.extend_from_slice(&[r.x, q.x, t.x, r.y, q.y, t.y, r.z, q.z, t.z]);
        }
        (pts, frames)
    }

    /// The scan over every edge that the hierarchy replaced (the reference of the test
    /// below): extensions, then the edges at the nearest sample, then all others by index,
    /// each replacing the best only when strictly closer.
    fn locate_by_scan(sp: &SpineModel, p: DVec3) -> (usize, f64, f64) {
        let n = sp.len();
        let mut best = (f64::INFINITY, 0usize, 0.0f64, 0.0f64);
        let w = p - sp.c[0];
        let tau = w.dot(sp.t[0]);
        if tau < 0.0 && !sp.closed {
            best = ((w - tau * sp.t[0]).length_squared(), 0, 0.0, tau);
        }
        let w = p - sp.c[n - 1];
        let tau = w.dot(sp.t[n - 1]);
        if tau > 0.0 && !sp.closed {
            let d2 = (w - tau * sp.t[n - 1]).length_squared();
            if d2 < best.0 {
                best = (d2, n - 2, 1.0, tau);
            }
        }
        let near = (0..n)
            .map(|i| ((p - sp.c[i]).length_squared(), i))
            .fold((f64::INFINITY, 0), |a, b| if b.0 < a.0 { b } else { a })
            .1;
        let first = near.saturating_sub(1);
        let order =
            (first..(near + 1).min(n - 1)).chain((0..n - 1).filter(|&k| k + 1 < near || k > near));
        for k in order {
            for a in edge_roots(sp, k, p) {
                if !(-1e-12..=1.0 + 1e-12).contains(&a) {
                    continue;
                }
                let a = a.clamp(0.0, 1.0);
                let d2 = (p - sp.c_at(k, a)).length_squared();
                if d2 < best.0 {
                    best = (d2, k, a, 0.0);
                }
            }
        }
        (best.1, best.2, best.3)
    }

    #[test]
    fn the_hierarchy_finds_the_sections_of_the_scan_bit_for_bit() {
        // a wavy open spine and a closed circle; points near and far, on sample planes and
        // at samples (ties between two edges' ends)
        let n = 300;
        let pts: Vec<DVec3> = (0..n)
            .map(|i| {
                let u = i as f64 * 0.05;
                DVec3::new(u, (2.0 * u).sin() * 0.5, (0.7 * u).cos() * 0.3)
            })
            .collect();
        let sp = model(&pts);
        let (cpts, cframes) = circle(64);
        let loop_sp = SpineModel::new("rest_spine", &cpts, &cframes, true, &cancel::never).unwrap();
        // far from the origin with short edges: the round-off of positions of size 1e4
        // exceeds the edges' own scale, which the bounds must allow for
        let far: Vec<DVec3> = (0..n)
            .map(|i| {
                DVec3::new(
                    1e4 + i as f64 * 0.01,
                    1e4 + (i as f64 * 0.02).sin() * 0.01,
                    1e4,
                )
            })
            .collect();
        let far_sp = model(&far);
        for (model, count) in [(&sp, 4000), (&loop_sp, 2000), (&far_sp, 4000)] {
            let edges = Edges::new(model).unwrap();
            let mut run = Vec::new();
            for q in 0..count {
                let x = q as f64 * 0.618_033_988_7;
                let mut p = DVec3::new(
                    (x * 3.1).sin() * 8.0 + 7.0,
                    (x * 1.7).cos() * 1.5,
                    (x * 0.9).sin() * 1.2,
                );
                if model.closed {
                    p = DVec3::new((x * 3.1).sin() * 1.6, (x * 1.7).cos() * 1.6, x.sin() * 0.4);
                }
                if std::ptr::eq(model, &far_sp) {
                    // within 1e-6 … 1e-2 of the spine (model units), often on sample planes
                    let j = 1 + q % (n - 2);
                    let off = 10f64.powf(-6.0 + 4.0 * (x * 7.3).sin().abs());
                    p = model.c[j] + DVec3::new(0.0, off * (x * 2.1).cos(), off * (x * 2.1).sin());
                }
                if q % 10 == 0 {
                    p = model.c[q % model.len()]; // on a sample
                }
                let mut s = Scratch {
                    hint: q * 7 % model.len(),
                    stack: Vec::new(),
                };
                let got = locate(model, &edges, p, &mut s);
                let want = locate_by_scan(model, p);
                assert_eq!(
                    (got.0, got.1.to_bits(), got.2.to_bits()),
                    (want.0, want.1.to_bits(), want.2.to_bits()),
                    "{p}"
                );
                run.push((p, want));
            }
            // the same points registered as one run (hints from the vertex before, four
            // at a time), in input units
            let to_input = model.scale.inverse();
            let pts: Vec<DVec3> = run.iter().map(|r| to_input.of3(r.0)).collect();
            let b = bind(model, &pts, &cancel::never).unwrap();
            for (i, (p, want)) in run.iter().enumerate() {
                let got = (
                    b.edge[i] as usize,
                    b.coords[COORDS * i],
                    b.coords[COORDS * i + 1],
                );
                assert_eq!(
                    (got.0, got.1.to_bits(), got.2.to_bits()),
                    (want.0, want.1.to_bits(), to_input.of(want.2).to_bits()),
                    "{p}"
                );
            }
        }
    }

    #[test]
    fn a_tube_about_a_straight_spine_binds_as_the_scan_does() {
        // rings of vertices about a straight spine (the vertex before is on the same edge
        // but at the sample planes), rings on the sample planes themselves (ties between
        // the two edges of a sample, decided by the nearest sample), and past both ends
        let n = 26;
        let pts: Vec<DVec3> = (0..n)
            .map(|i| DVec3::new(i as f64 * 0.16, 0.0, 0.0))
            .collect();
        let sp = model(&pts);
        let mut verts = Vec::new();
        for ring in 0..300 {
            let x = if ring % 5 == 0 {
                0.16 * (ring / 5) as f64 // on a sample plane
            } else {
                -0.2 + 4.4 * ring as f64 / 300.0
            };
            for j in 0..37 {
                let ang = std::f64::consts::TAU * j as f64 / 37.0;
                verts.push(DVec3::new(x, 0.3 * ang.cos(), 0.3 * ang.sin()));
            }
        }
        let b = bind(&sp, &verts, &cancel::never).unwrap();
        let mut ties = 0;
        for (i, &p) in verts.iter().enumerate() {
            let want = locate_by_scan(&sp, p);
            let got = (
                b.edge[i] as usize,
                b.coords[COORDS * i],
                b.coords[COORDS * i + 1],
            );
            assert_eq!(
                (got.0, got.1.to_bits(), got.2.to_bits()),
                (want.0, want.1.to_bits(), want.2.to_bits()),
                "{p}"
            );
            // on a sample plane inside the spine (the first edge of the tie wins)
            ties += usize::from((want.1 == 0.0 || want.1 == 1.0) && want.2 == 0.0);
        }
        assert!(ties > 100, "{ties}");
    }

    #[test]
    fn loops_bind_on_the_closing_edge_and_on_sample_planes() {
        let (pts, frames) = circle(12);
        let sp = SpineModel::new("rest_spine", &pts, &frames, true, &cancel::never).unwrap();
        // the curvature at the seam is that of every other sample, from both sides
        let inner = sp.eval(6, 0.0).kappa.length();
        assert!((inner - 1.0).abs() < 0.04);
        for (k, a) in [(0, 0.0), (11, 1.0)] {
            let l = sp.eval(k, a);
            assert!(
                (l.kappa.length() - inner).abs() < 1e-12,
                "{k} {a}: {}",
                l.kappa
            );
        }
        // points in the closing edge's slab, on sample planes (angle π: sample 6), and
        // outside the ring: never past an end
        for ang in [-0.2_f64, -0.01, 0.0, std::f64::consts::PI, 1.3] {
            for rad in [0.7, 1.25] {
                let p = DVec3::new(rad * ang.cos(), rad * ang.sin(), 0.1);
                let b = bind(&sp, &[p], &cancel::never).unwrap();
                let (k, a, tau) = (b.edge[0] as usize, b.coords[0], b.coords[1]);
                assert_eq!(tau, 0.0);
                let l = sp.eval(k, a);
                let d = p - l.q;
                assert!(
                    d.dot(l.t).abs() < 1e-12 && d.length() < 0.35,
                    "{ang} {rad}: {k} {a}"
                );
                if ang < 0.0 {
                    assert_eq!(k, 11);
                }
            }
        }
        // an open spine's point past its end extends the end instead
        let open = SpineModel::new(
            "rest_spine",
            &pts[..7],
            &frames[..63],
            false,
            &cancel::never,
        )
        .unwrap();
        let b = bind(&open, &[DVec3::new(-1.0, -0.2, 0.0)], &cancel::never).unwrap();
        assert!(b.coords[1] > 0.0);
        // a loop must repeat its first point
        assert!(
            SpineModel::new(
                "rest_spine",
                &pts[..12],
                &frames[..108],
                true,
                &cancel::never
            )
            .is_err()
        );
    }
}
