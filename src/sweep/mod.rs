//! Sweep surfaces: a profile polygon carried along a spine by moving frames, as a triangle
//! mesh with normals and texture coordinates.
//!
//! Ring `i` (one per spine sample) holds the profile vertices
//!
//! ```text
//! v_ij = x_i + M_i (a′_j r_i + b′_j s_i),   (a′, b′) = Rot(θ_i) · (σ_i,a a_j, σ_i,b b_j)
//! ```
//!
//! with the frame `(r_i, s_i, t_i)`, the per-sample scale `σ_i` (per profile axis) and twist
//! `θ_i`. `M_i` is the **mitre stretch**: where the spine turns by the angle `φ` between its
//! incoming and outgoing chords, the ring is stretched by `1/cos(φ/2)` along the in-plane
//! direction of the turn, so that a ring lying in the bisector plane of a corner is exactly
//! the cut of both adjacent straight prisms — the tube keeps its cross-section through the
//! corner instead of pinching (VTK's tube filter leaves this correction commented out).
//! On smoothly sampled curves `1/cos(φ/2) = 1 + κ²h²/8 + …`, a second-order change. The
//! stretch is capped by `miter_limit`.
//!
//! **Faces** join ring `i` to ring `i + 1` (and the last ring to the first on a closed
//! spine) vertex to vertex, two triangles per quad, wound so that the normals point to the
//! right of the profile's direction of travel, which is outwards for a counter-clockwise
//! closed profile; clockwise closed profiles are wound the other way, so closed sweeps always
//! face outwards. Caps are the ear-clipping triangulation of the profile on the first and
//! last rings. Every vertex is shared by all its faces, so closed sweeps and capped open
//! sweeps are watertight by construction.
//!
//! **Normals** are those of the smooth swept surface `S(u, v)`: `n ∝ S_v × S_u` from
//! differences of the ring vertices — around the profile (central) and along the spine (the
//! three-point derivative in arc length, one-sided at open ends). They therefore include the
//! tilt `−dρ/ds · t` of a variable radius, the twist and the mitre, and are exact on
//! cylinders, cones and tori sampled evenly.
//!
//! **Fold-over.** Where the profile reaches past the centre of curvature (`1 − κ ρ cos ψ ≤ 0`)
//! the surface folds over itself. The discrete test used here: every rail edge
//! `v_{i+1,j} − v_{ij}` must advance along both `t_i` and `t_{i+1}`; segments that fail are
//! reported.
//!
//! **Texture coordinates**: `u` = arc length of the spine polyline at the ring, `v` = arc
//! length around the profile divided by its perimeter.

pub mod profile;

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use crate::error::{InputError, Result};
use crate::frames::validate;
pub use profile::Profile;

/// One spine with its per-sample data (all slices have the spine's row count).
#[derive(Debug, Clone, Copy)]
pub struct Spine<'a> {
    pub points: &'a [DVec3],
    /// Row-major `(n, 3, 3)` frames, columns `(r, s, t)`.
    pub frames: &'a [[f64; 9]],
    /// Scale along the profile's `(a, b)` axes.
    pub scale: &'a [DVec2],
    /// Twist about the tangent, radians (empty: none).
    pub twist: &'a [f64],
}

/// Options shared by all spines of a sweep.
#[derive(Debug, Clone, Copy)]
pub struct Options {
    pub closed: bool,
    pub caps: bool,
    pub miter_limit: f64,
    /// Duplicate the vertices on the texture seams (see [`sweep_many`]).
    pub split_seams: bool,
}

/// A triangle mesh.
#[derive(Debug, Clone, Default)]
pub struct Mesh {
    pub vertices: Vec<DVec3>,
    pub faces: Vec<[i64; 3]>,
    pub normals: Vec<DVec3>,
    /// Texture coordinates: `u` spine arc length, `v` profile arc length / perimeter.
    pub uv: Vec<DVec2>,
    /// Spine rows (global, as given) starting a segment where the sweep folds over.
    pub folds: Vec<usize>,
}

#[inline]
fn columns(f: &[f64; 9]) -> (DVec3, DVec3, DVec3) {
    (
        DVec3::new(f[0], f[3], f[6]),
        DVec3::new(f[1], f[4], f[7]),
        DVec3::new(f[2], f[5], f[8]),
    )
}

/// Layout of one spine's part of the mesh.
#[derive(Debug, Clone)]
struct Plan {
    /// Distinct spine samples.
    rings: usize,
    segments: usize,
    caps: bool,
    /// Rings stored (one more than `rings` for a closed spine with split seams).
    stored_rings: usize,
    /// Vertices per stored ring (one more than the profile for a closed profile with split
    /// seams).
    cols: usize,
    /// Arc length of the spine polyline at every ring (and after the closing chord).
    arc: Vec<f64>,
}

impl Plan {
    fn vertices(&self) -> usize {
        self.stored_rings * self.cols
    }
    fn faces(&self, p: &Profile) -> usize {
        let edges = if p.closed { p.len() } else { p.len() - 1 };
        2 * self.segments * edges + if self.caps { 2 * (p.len() - 2) } else { 0 }
    }
}

fn check_spine(s: &Spine, opts: &Options, p: &Profile) -> Result<Plan> {
    let n = s.points.len();
    if s.frames.len() != n {
        return Err(InputError::new(
            "frames",
            format!("has {} rows but points has {n}", s.frames.len()),
        ));
    }
    if s.scale.len() != n {
        return Err(InputError::new(
            "scale",
            format!("has {} rows but points has {n}", s.scale.len()),
        ));
    }
    if !s.twist.is_empty() && s.twist.len() != n {
        return Err(InputError::new(
            "twist",
            format!("has {} entries but points has {n} rows", s.twist.len()),
        ));
    }
    validate::finite("points", s.points)?;
    let mut rings = n;
    if opts.closed && n >= 2 && validate::coincide(s.points[0], s.points[n - 1]) {
        rings -= 1;
    }
    let min = if opts.closed { 3 } else { 2 };
    if rings < min {
        return Err(InputError::new(
            "points",
            format!(
                "a{} spine needs at least {min} distinct points, got {rings}",
                if opts.closed { " closed" } else { "n open" }
            ),
        ));
    }
    let chords = validate::chords(&s.points[..rings], opts.closed)?;
    if let Some(i) = validate::first_bad(s.frames, validate::is_rotation) {
        return Err(InputError::new(
            "frames",
            format!(
                "row {i} is not a rotation matrix (columns r, s, t must be orthonormal and \
                 right-handed; use spinal.frames)"
            ),
        ));
    }
    if let Some(i) = validate::first_bad(s.scale, |v| v.x > 0.0 && v.y > 0.0 && v.is_finite()) {
        return Err(InputError::new(
            "scale",
            format!(
                "must be positive and finite, got {:?} at row {i} (for a pointed end use a \
                 small positive value)",
                s.scale[i].to_array()
            ),
        ));
    }
    if let Some(i) = validate::first_bad(s.twist, |v| v.is_finite()) {
        return Err(InputError::new(
            "twist",
            format!("non-finite value at row {i}"),
        ));
    }
    let mut arc = Vec::with_capacity(chords.len() + 1);
    let mut acc = 0.0;
    arc.push(acc);
    for c in chords {
        acc += c;
        arc.push(acc);
    }
    Ok(Plan {
        rings,
        segments: if opts.closed { rings } else { rings - 1 },
        caps: opts.caps && !opts.closed && p.closed,
        stored_rings: rings + usize::from(opts.closed && opts.split_seams),
        cols: p.len() + usize::from(p.closed && opts.split_seams),
        arc,
    })
}

/// Mitre stretch at ring `i`: `(factor − 1, unit direction)`, or zero where the spine is
/// straight or at an open end.
fn mitre(x: &[DVec3], t: DVec3, i: usize, closed: bool, limit: f64) -> (f64, DVec3) {
    let n = x.len();
    if !closed && (i == 0 || i + 1 == n) {
        return (0.0, DVec3::ZERO);
    }
    let prev = x[(i + n - 1) % n];
    let next = x[(i + 1) % n];
    let din = (x[i] - prev).normalize();
    let dout = (next - x[i]).normalize();
    let half_cos = 0.5 * (1.0 + din.dot(dout)); // cos²(φ/2)
    let k = din - dout;
    let k = k - k.dot(t) * t;
    let kl = k.length();
    if !(kl > 1e-12) || !(half_cos > 0.0) {
        return (0.0, DVec3::ZERO);
    }
    let factor = (1.0 / half_cos.sqrt()).min(limit);
    (factor - 1.0, k / kl)
}

/// Three-point derivative weights at the middle of samples spaced `h1`, `h2`.
#[inline]
fn central_weights(h1: f64, h2: f64) -> [f64; 3] {
    [
        -h2 / (h1 * (h1 + h2)),
        (h2 - h1) / (h1 * h2),
        h1 / (h2 * (h1 + h2)),
    ]
}

/// Derivative along the spine at ring `i`: three rings and their weights (three-point rule
/// in arc length; one-sided at open ends; two points for a two-sample spine).
fn spine_weights(arc: &[f64], i: usize, r_n: usize, closed: bool) -> ([usize; 3], [f64; 3]) {
    if closed {
        let (a, b) = ((i + r_n - 1) % r_n, (i + 1) % r_n);
        let h1 = if i == 0 {
            arc[r_n] - arc[r_n - 1]
        } else {
            arc[i] - arc[i - 1]
        };
        let h2 = arc[i + 1] - arc[i];
        ([a, i, b], central_weights(h1, h2))
    } else if r_n == 2 {
        let h = arc[1] - arc[0];
        ([0, 1, 1], [-1.0 / h, 1.0 / h, 0.0])
    } else if i == 0 || i + 1 == r_n {
        let (i0, i1, i2) = if i == 0 {
            (0, 1, 2)
        } else {
            (r_n - 1, r_n - 2, r_n - 3)
        };
        let h1 = (arc[i1] - arc[i0]).abs();
        let h2 = (arc[i2] - arc[i1]).abs();
        let sg = if i == 0 { 1.0 } else { -1.0 };
        (
            [i0, i1, i2],
            [
                -sg * (2.0 * h1 + h2) / (h1 * (h1 + h2)),
                sg * (h1 + h2) / (h1 * h2),
                -sg * h1 / (h2 * (h1 + h2)),
            ],
        )
    } else {
        let h1 = arc[i] - arc[i - 1];
        let h2 = arc[i + 1] - arc[i];
        ([i - 1, i, i + 1], central_weights(h1, h2))
    }
}

/// Output buffers of a sweep, sized by [`Layout`]; every element is written.
#[derive(Debug)]
pub struct MeshMut<'a> {
    pub vertices: &'a mut [DVec3],
    pub faces: &'a mut [[i64; 3]],
    pub normals: &'a mut [DVec3],
    /// Texture coordinates `(u, v)`, as in [`Mesh::uv`].
    pub uv: &'a mut [DVec2],
}

/// The checked input of a sweep and the size of its mesh, from [`layout`].
#[derive(Debug, Clone)]
pub struct Layout {
    plans: Vec<Plan>,
    pub vertices: usize,
    pub faces: usize,
}

/// Sweep one spine into its share of the output buffers; returns the rows (global) that
/// start a folded-over segment.
fn sweep_one(
    s: &Spine,
    plan: &Plan,
    p: &Profile,
    opts: &Options,
    vbase: usize,
    rowbase: usize,
    out: MeshMut,
) -> Vec<usize> {
    let m = p.len();
    let r_n = plan.rings;
    let cols = plan.cols;
    let x = &s.points[..r_n];
    let arc = &plan.arc;
    let closed = opts.closed;
    // Rings per parallel task: enough work (~4k vertices) to pay for the task.
    let grain = (4096 / cols).max(1);
    // Winding: normals to the right of the profile's direction, outward for closed profiles.
    let sign = if p.closed && p.area < 0.0 { -1.0 } else { 1.0 };
    let tangent = |k: usize| columns(&s.frames[k]).2;
    // Ring k of the smooth swept surface: centre and the images of the profile axes.
    let base = |k: usize| -> (DVec3, DVec3, DVec3) {
        let (r, q, _) = columns(&s.frames[k]);
        let sc = s.scale[k];
        let (sn, cs) = if s.twist.is_empty() {
            (0.0, 1.0)
        } else {
            s.twist[k].sin_cos()
        };
        (x[k], sc.x * (cs * r + sn * q), sc.y * (cs * q - sn * r))
    };
    let mitre_at = |k: usize| mitre(x, tangent(k), k, closed, opts.miter_limit);

    // One pass over the stored rings: positions (mitred), normals of the smooth surface
    // (un-mitred: the mitre is a discretisation correction and would tilt them), uv, and the
    // fold-over test of the segment starting there. Stored ring `i` is spine sample
    // `i mod rings`, stored column `j` is profile vertex `j mod m` (the duplicates of split
    // seams carry u = L and v = 1). Nothing is read back from the outputs but the ring just
    // written; rings go in blocks so that each ring's geometry is computed once.
    #[derive(Clone, Copy)]
    struct Geo {
        k: usize,
        /// Centre and profile axes of the smooth surface.
        b: (DVec3, DVec3, DVec3),
        /// The axes with the mitre stretch `M(a) = a + (f − 1)(a·k)k`: vertex `j` is
        /// `x + a_j·ma + b_j·mb`.
        ma: DVec3,
        mb: DVec3,
        t: DVec3,
    }
    let geo = |k: usize| {
        let b = base(k);
        let (mf, mk) = mitre_at(k);
        Geo {
            k,
            b,
            ma: b.1 + (mf * b.1.dot(mk)) * mk,
            mb: b.2 + (mf * b.2.dot(mk)) * mk,
            t: tangent(k),
        }
    };
    // Per stored column: the profile vertex, the difference of its neighbours (the derivative
    // around the profile, central; one-sided at the ends of an open profile) and v.
    struct Column {
        p: DVec2,
        /// `(dp.x, dp.y, dp.x p.x, dp.x p.y, dp.y p.x, dp.y p.y)`: the weights of the ring's
        /// six cross products in the normal (see below).
        w: [f64; 6],
        v: f64,
    }
    let column: Vec<Column> = (0..cols)
        .map(|j| {
            let jj = if j == m { 0 } else { j };
            let (jp, jn) = if p.closed {
                ((jj + m - 1) % m, (jj + 1) % m)
            } else {
                (jj.saturating_sub(1), (jj + 1).min(m - 1))
            };
            let (pj, dp) = (p.points[jj], p.points[jn] - p.points[jp]);
            Column {
                p: pj,
                w: [
                    dp.x,
                    dp.y,
                    dp.x * pj.x,
                    dp.x * pj.y,
                    dp.y * pj.x,
                    dp.y * pj.y,
                ],
                v: if j == m { 1.0 } else { p.v[j] },
            }
        })
        .collect();
    let block = grain * cols;
    let folds: Vec<usize> = out
        .vertices
        .par_chunks_mut(block)
        .zip(out.normals.par_chunks_mut(block))
        .zip(out.uv.par_chunks_mut(block))
        .enumerate()
        .flat_map_iter(|(bi, ((bv, bn), bu))| {
            let i0 = bi * grain;
            let mut folds = Vec::new();
            let mut prev = geo((i0 + r_n - 1) % r_n);
            let mut cur = geo(i0 % r_n);
            let rings = bv
                .chunks_mut(cols)
                .zip(bn.chunks_mut(cols))
                .zip(bu.chunks_mut(cols));
            for (di, ((rv, rn), ruv)) in rings.enumerate() {
                let i = i0 + di;
                let k = cur.k;
                let next = geo((i + 1) % r_n);
                let b = cur.b;
                // d/ds of the ring: the same weights on centres and axes.
                let (idx, w) = spine_weights(arc, k, r_n, closed);
                let (mut dx, mut da, mut db) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
                for (&ii, &wi) in idx.iter().zip(&w) {
                    let bi = match ii {
                        _ if ii == k => b,
                        _ if ii == next.k => next.b,
                        _ if ii == prev.k => prev.b,
                        _ => base(ii),
                    };
                    dx += wi * bi.0;
                    da += wi * bi.1;
                    db += wi * bi.2;
                }
                // The normal S_v × S_u with S_v ∝ e = dp.x b₁ + dp.y b₂ (around the profile)
                // and S_u = dx + p.x da + p.y db (along the spine) is bilinear in the column's
                // (dp, p): six cross products per ring, six weights per column.
                let cr = [
                    sign * b.1.cross(dx),
                    sign * b.2.cross(dx),
                    sign * b.1.cross(da),
                    sign * b.1.cross(db),
                    sign * b.2.cross(da),
                    sign * b.2.cross(db),
                ];
                for (c, ((v, nv), w)) in
                    column.iter().zip(rv.iter_mut().zip(rn.iter_mut()).zip(ruv))
                {
                    let cw = &c.w;
                    let nn = cw[0] * cr[0]
                        + cw[1] * cr[1]
                        + cw[2] * cr[2]
                        + cw[3] * cr[3]
                        + cw[4] * cr[4]
                        + cw[5] * cr[5];
                    *nv = nn.try_normalize().unwrap_or_else(|| {
                        // degenerate spine derivative: the normal of the ring plane
                        let e = cw[0] * b.1 + cw[1] * b.2;
                        (sign * e.cross(cur.t)).try_normalize().unwrap_or(cur.t)
                    });
                    *v = b.0 + c.p.x * cur.ma + c.p.y * cur.mb;
                    *w = DVec2::new(arc[i], c.v);
                }
                // Fold-over: rail edges must advance along both tangents. The rail edge of
                // profile vertex p is (x′ − x) + p_a (ma′ − ma) + p_b (mb′ − mb), so its
                // components along t and t′ are affine in p.
                if i < plan.segments {
                    let (dx0, dma, dmb) = (next.b.0 - b.0, next.ma - cur.ma, next.mb - cur.mb);
                    let along = |t: DVec3| (dx0.dot(t), DVec2::new(dma.dot(t), dmb.dot(t)));
                    let ((c1, g1), (c2, g2)) = (along(cur.t), along(next.t));
                    let folded = p
                        .points
                        .iter()
                        .any(|&pj| !(c1 + pj.dot(g1) > 0.0 && c2 + pj.dot(g2) > 0.0));
                    if folded {
                        folds.push(rowbase + i);
                    }
                }
                prev = cur;
                cur = next;
            }
            folds
        })
        .collect();

    // Side faces. Without split seams the last column/ring wraps to the first.
    let edges = if p.closed { m } else { m - 1 };
    let (side, caps) = out.faces.split_at_mut(2 * plan.segments * edges);
    let col = |j: usize| if j == cols { 0 } else { j };
    let row = |i: usize| if i == plan.stored_rings { 0 } else { i };
    side.par_chunks_mut(2 * edges)
        .with_min_len(grain)
        .enumerate()
        .for_each(|(i, quads)| {
            let id = |ii: usize, jj: usize| (vbase + row(ii) * cols + col(jj)) as i64;
            for j in 0..edges {
                let (a, b, c, d) = (id(i, j), id(i, j + 1), id(i + 1, j + 1), id(i + 1, j));
                if sign > 0.0 {
                    quads[2 * j] = [a, b, c];
                    quads[2 * j + 1] = [a, c, d];
                } else {
                    quads[2 * j] = [a, c, b];
                    quads[2 * j + 1] = [a, d, c];
                }
            }
        });
    if plan.caps {
        let tris = p.triangulate();
        let last = (vbase + (r_n - 1) * cols) as i64;
        let first = vbase as i64;
        let k = tris.len();
        for (c, tr) in tris.iter().enumerate() {
            let [a, b, d] = tr.map(|v| v as i64);
            caps[c] = [first + a, first + d, first + b]; // faces −t
            caps[k + c] = [last + a, last + b, last + d]; // faces +t
        }
    }
    folds
}

fn part<'a>(all: &Spine<'a>, offsets: &[usize], c: usize) -> Spine<'a> {
    let (a, b) = (offsets[c], offsets[c + 1]);
    Spine {
        points: &all.points[a..b],
        frames: &all.frames[a..b],
        scale: &all.scale[a..b],
        twist: if all.twist.is_empty() {
            &[]
        } else {
            &all.twist[a..b]
        },
    }
}

/// Check a bundle of spines (`offsets[c]..offsets[c+1]` are the rows of spine `c` in the
/// flat arrays) and size its mesh.
pub fn layout(all: &Spine, offsets: &[usize], profile: &Profile, opts: &Options) -> Result<Layout> {
    let curves = offsets.len().saturating_sub(1);
    let n = all.points.len();
    validate::offsets(offsets, n)?;
    if !(opts.miter_limit >= 1.0) {
        return Err(InputError::new(
            "miter_limit",
            format!(
                "must be ≥ 1 (1 disables the mitre stretch), got {}",
                opts.miter_limit
            ),
        ));
    }
    let plans: Vec<Plan> = (0..curves)
        .into_par_iter()
        .map(|c| {
            check_spine(&part(all, offsets, c), opts, profile).map_err(|e| {
                if curves > 1 {
                    e.context(&format!(
                        "curve {c} (rows {} to {})",
                        offsets[c],
                        offsets[c + 1].max(1) - 1
                    ))
                } else {
                    e
                }
            })
        })
        .collect::<Result<_>>()?;
    Ok(Layout {
        vertices: plans.iter().map(Plan::vertices).sum(),
        faces: plans.iter().map(|p| p.faces(profile)).sum(),
        plans,
    })
}

/// Sweep `profile` along every spine of a checked bundle into buffers of the sizes in
/// `layout` (spines in parallel). Returns the rows starting a folded-over segment.
pub fn sweep_into(
    all: &Spine,
    offsets: &[usize],
    profile: &Profile,
    opts: &Options,
    layout: &Layout,
    out: MeshMut,
) -> Vec<usize> {
    let (nv, nf) = (layout.vertices, layout.faces);
    assert!(
        out.vertices.len() == nv
            && out.normals.len() == nv
            && out.uv.len() == nv
            && out.faces.len() == nf,
        "sweep_into: buffers must have the sizes of the layout"
    );
    // Split the buffers per spine.
    let mut jobs = Vec::with_capacity(layout.plans.len());
    let (mut v, mut nr, mut u, mut f) = (out.vertices, out.normals, out.uv, out.faces);
    let mut vbase = 0;
    for (c, plan) in layout.plans.iter().enumerate() {
        let (k, kf) = (plan.vertices(), plan.faces(profile));
        let (v1, v2) = v.split_at_mut(k);
        let (n1, n2) = nr.split_at_mut(k);
        let (u1, u2) = u.split_at_mut(k);
        let (f1, f2) = f.split_at_mut(kf);
        let mine = MeshMut {
            vertices: v1,
            faces: f1,
            normals: n1,
            uv: u1,
        };
        jobs.push((c, vbase, mine));
        (v, nr, u, f) = (v2, n2, u2, f2);
        vbase += k;
    }
    let folds: Vec<Vec<usize>> = jobs
        .into_par_iter()
        .map(|(c, vbase, mine)| {
            sweep_one(
                &part(all, offsets, c),
                &layout.plans[c],
                profile,
                opts,
                vbase,
                offsets[c],
                mine,
            )
        })
        .collect();
    folds.concat()
}

/// [`layout`] and [`sweep_into`] with freshly allocated buffers.
pub fn sweep_many(
    all: &Spine,
    offsets: &[usize],
    profile: &Profile,
    opts: &Options,
) -> Result<Mesh> {
    let lay = layout(all, offsets, profile, opts)?;
    let mut mesh = Mesh {
        vertices: vec![DVec3::ZERO; lay.vertices],
        faces: vec![[0; 3]; lay.faces],
        normals: vec![DVec3::ZERO; lay.vertices],
        uv: vec![DVec2::ZERO; lay.vertices],
        folds: Vec::new(),
    };
    mesh.folds = sweep_into(
        all,
        offsets,
        profile,
        opts,
        &lay,
        MeshMut {
            vertices: &mut mesh.vertices,
            faces: &mut mesh.faces,
            normals: &mut mesh.normals,
            uv: &mut mesh.uv,
        },
    );
    Ok(mesh)
}
