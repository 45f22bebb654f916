//! A closed triangle mesh carried along a field, refined *during* the integration.
//!
//! A triangle mesh follows a flow only at its vertices; between them its faces stay flat, so
//! the mesh's volume error grows with the square of the deformed edges. Zheng (thesis
//! §13.2) keeps the mesh resolved by splitting edges that the flow stretched beyond a
//! threshold — the two triangles sharing the edge are bisected ("2 to 4") — and, in the
//! smoother variant, by placing the new vertex at the image of the rest midpoint under the
//! same flow. Here the edges are tested after every integration step, so a new vertex is
//! carried on from the step at which its edge first grew too long and the refinement follows
//! the stretch instead of chasing it afterwards:
//!
//! * **threshold** — edge `(a, b)` is too long when `|W_a − W_b| > τ · max(|X_a − X_b|, ℓ̄)`,
//!   `W` the current and `X` the rest positions, `ℓ̄` the mean rest edge length and
//!   `τ = refine ≥ 1`. An edge that is long already at rest is split only where the flow
//!   stretches it, and a mesh the field never moves is never split;
//! * **longest-edge bisection** (Rivara 1984, 1997) — an edge over the threshold is refined
//!   through its longest-edge propagation path: from its triangle to the neighbour across
//!   that triangle's longest edge, until an edge is the longest of both its triangles (the
//!   terminal edge), which is split, whether or not it is over the threshold itself. A
//!   split only ever halves triangles across their longest edge, so no angle falls below half
//!   the smallest angle it came from and the splits end. Splitting the over-long edge
//!   itself where a longer edge of its triangle is not over the threshold (a long rest
//!   edge, whose threshold is higher) can cycle: two such splits in turn converge to a fixed
//!   point and stack copies of one vertex (a rocker arm's long CAD triangles under a
//!   fandisk-shaped tool got 39, with 150 faces of zero area);
//! * **placement** — the rest midpoint `m = (X_a + X_b)/2` is integrated through the steps
//!   taken so far, which gives the bits of advecting `m` from the start (the refined mesh is
//!   `Φ(rest)` vertex by vertex);
//! * **slip surfaces** — across the surface of a curl tool only the normal velocity is
//!   continuous (thesis §12.1; [`super::Tool::slip_surface`]): the material at rest inside
//!   the tool and the material outside it part along the surface, and a mesh edge across it
//!   is *torn*. The deformed body's boundary then runs from the images of the outer side over
//!   a strip of the tool's surface to the images of the inner side. Its points are the
//!   images of a *generalized* rest mesh ([`super::slip`]): material points `X`, carried by
//!   `Φ` — near the surface by the one-sided velocity `v₊` or `v₋` of the side where `X` lies
//!   at rest, since RK4 stages that step across the surface would otherwise carry a point
//!   into the other side's slip — and surface points `(p, s)`, `p` on the surface at rest and
//!   `s ∈ [0, 1]`, carried by the blend `v_s = (1 − s) v₊ + s v₋` to `Ψ(p, s)`. Both one-sided
//!   limits have the surface's normal velocity, so `Ψ(p, s)` stays on the surface and sweeps
//!   the strip between `Φ₊(p) = Ψ(p, 0)` and `Φ₋(p) = Ψ(p, 1)` as `s` runs over `[0, 1]`
//!   (`s = ½` moves with the tool itself). An edge whose ends are surface points, or material
//!   points of different sides, runs along the path `X_a → p (side of a) → p (side of b) →
//!   X_b`, `p` where its rest segment meets the surface (or its surface end). Its new vertex
//!   is the point halfway along that path, measured by the chords between the images of the
//!   path's points: a material point of one side, or a surface point `(p, s)` with the mean
//!   blend. Both halves of the edge are then about half as long, so bisection resolves every
//!   torn edge and the refinement converges unless a bound stops it. Every new rest point
//!   lies on its rest edge, so the rest mesh keeps its volume.
//!
//!   Before, a torn edge's new vertex was its chord midpoint moved onto the tool's surface
//!   (a hair on its outer side, carried by the outer side's flow). For an edge from a vertex
//!   at depth `δ` inside the tool to a vertex on the surface, the projection lands next to
//!   the surface end, so the edge to the deep vertex stays at about `max(δ, its length)`:
//!   each step added a fan of vertices around the deep one (rest points converging to its
//!   own) without shortening it. On a 10k-vertex sphere dragged half a radius by a curl
//!   tool centred on its surface that left 186 edges over the threshold with 6.5× the
//!   vertices (at 40k, 134,116 at the 8× bound); with the halfway placement the refinement
//!   converges with 2.66× the vertices and a volume change of −4.2e-5 (3.31× and −1.5e-5 at
//!   40k);
//! * **corners** — halving the path can repeat itself. Where the strip of tool surface meets
//!   the material of one side, take two surface vertices of the same rest point, `n` near
//!   the bend (the junction's image) and `f` farther along the strip, and two material
//!   vertices, `m` just below the bend and `d` deeper. The edge `(m, f)` is split halfway
//!   along its path, onto the strip next to `n`; the new vertex's edge to `d` is over the
//!   threshold and split halfway along its path, onto the material next to `m`; that new
//!   vertex's edge to `f` is split again, and so on: each pair of passes adds two vertices,
//!   converging to copies of `n` and `m`, until `max_passes` stops the refinement with an
//!   edge still over the threshold (a 16,386-vertex octahedral sphere dragged like the
//!   sphere above in 40 steps kept 2 edges at 1.02× the threshold). Such a split puts its
//!   new vertex on a third vertex of its triangles (closer than `split::COINCIDENT` × the edge)
//!   and joins it to the other third vertex by an edge over the threshold and longer than
//!   the split one, which bisection at the chord midpoint never does (the median to a
//!   triangle's third vertex is shorter than its longest edge; Rivara 1984). Its new vertex
//!   goes to the corner of the path nearest to the halfway point instead: the junction where
//!   the path meets or leaves the surface, a point of the body's boundary, so that the two
//!   halves have one corner fewer;
//! * **chord midpoints** — where `Φ(m)` of an edge of one side's material lies farther than a
//!   quarter of the edge from the chord midpoint (a flow the steps do not resolve), the new
//!   vertex is the chord midpoint, moved onto the nearest slip surface a hair on its outer
//!   side when one passes within the edge length. Splitting a flat pair of triangles at a
//!   chord midpoint does not change the mesh's volume;
//! * **flips** — the strip along a slip surface is filled by vertices of few rest points
//!   each (a rest point's blends `s` lie on one curve `Ψ(p, ·)`), which bisection joins into
//!   slivers. After each step's splits, the edges of the split faces (and after the last step
//!   every edge with a vertex on the surface) are flipped where that raises the smaller
//!   smallest angle of their two triangles (Lawson's max-min angle flips; Lawson 1977,
//!   "Software for C¹ surface interpolation"), keeps the mesh edge-manifold and its winding,
//!   does not fold, keeps the rest mesh's volume and changes the enclosed volume by the
//!   tetrahedron of the four vertices, at most `10⁻⁴ ℓ̄³` (for the unit sphere of mean edge
//!   0.038 a thirteenth of the volume `≈ ℓ̄⁴/28` between one face and the sphere; the sum
//!   over all flips is [`Deformed::flip_volume`]). On
//!   the 10k-vertex drag this takes the band's faces with a smallest angle under 1° from
//!   48% to 32% and the vertices from 2.66× to 2.34×, the volume change unchanged;
//! * **collapses** — the slivers flips cannot mend (four vertices on one curve `Ψ(p, ·)`, or
//!   the strip narrowed to a line where the torn curve runs along the slip) and the faces
//!   folded back at the lip are collapsed after the integration, on a converged refinement:
//!   edge collapses under the link condition with the survivor on the slip surface where it
//!   keeps the enclosed volume, and moves of strip vertices towards their neighbours'
//!   centroid (Hoppe et al., "Mesh optimization", SIGGRAPH 1993; see `refine/collapse.rs`). On the
//!   10k-vertex drag the band's slivers go from 32% to 1.3%, the vertices from 2.34× to
//!   1.90×, the volume change from −4.18e-5 to −4.22e-5;
//! * **bending** — after the integration, edges the flow bends (`Φ` of the rest midpoint
//!   farther than 0.06 of the edge from the chord, or, away from slip surfaces, its
//!   deviation accounting for more than 2e-3 of the rest volume per input edge) are split
//!   the same way, in rounds (`refine/bend.rs`): lengths alone miss a press into a long
//!   face, a twist, or a sharp bend that folds flat faces over their neighbours;
//! * **bounds** — at most `max_passes` passes per step and `max_vertices` vertices in all.
//!   When edges remain over the threshold at the end — a bound stopped the refinement — the
//!   result says so (`bounded`, and the number of those edges).
//!
//! The rate of change of a mesh's volume is the flux of its linearly interpolated vertex
//! velocities, which differs from the zero flux of a divergence-free `v` through the same
//! closed surface by `O(ℓ² |∇²v|)` per unit area: keeping every edge below `τ ℓ̄` keeps the
//! mesh error at the resolution of the rest mesh.
//!
//! The splits (threshold, bisection, placement) are in `refine/split.rs`, the bending splits
//! in `refine/bend.rs`, the flips in
//! `refine/flip.rs`, the collapses in `refine/collapse.rs`; this file holds the mesh, the
//! refinement state and the integration loop ([`deform`]).

use crate::run::cancel;
use std::time::Instant;

use glam::DVec3;
use rayon::prelude::*;

use super::Field;
use super::advect::{Method, advect_steps};
use super::slip::{self, Carry};
use crate::error::{InputError, Result};
use crate::run::alloc;

mod bend;
mod collapse;
mod flip;
mod split;
#[cfg(test)]
mod tests;

/// No twin: a boundary half-edge.
const NONE: usize = usize::MAX;

/// The call named in out-of-memory errors.
const CALL: &str = "deform";

/// The flips' test of whether the new edge exists walks at most this many edges around a
/// vertex (a vertex with more neighbours is left alone).
const MAX_VALENCE: usize = 1024;

pub use super::advect::Run;

/// The steps of an integration from `t0` over `duration` in about `steps` equal steps, ended
/// at the field's breakpoints ([`Field::breakpoints`]: a path tool's velocity is only C⁰ in
/// time there) with `⌈steps·|b − a|/|duration|⌉ ≥ 1` steps on each sub-interval `[a, b]`.
/// The list (one run per breakpoint inside) is allocated fallibly (the out-of-memory error
/// names `deform`).
pub fn schedule(field: &Field, t0: f64, duration: f64, steps: usize) -> Result<Vec<Run>> {
    if duration == 0.0 || steps == 0 {
        return Ok(Vec::new());
    }
    let t1 = t0 + duration;
    let (lo, hi) = (t0.min(t1), t0.max(t1));
    let mut cuts = field.breakpoints(CALL)?;
    cuts.retain(|&b| b > lo && b < hi);
    if cuts.is_empty() {
        return Ok(vec![Run {
            t0,
            h: duration / steps as f64,
            count: steps,
        }]);
    }
    if duration < 0.0 {
        cuts.reverse();
    }
    let mut ts = alloc::with_capacity(CALL, cuts.len() + 2)?;
    ts.push(t0);
    ts.extend(cuts);
    ts.push(t1);
    alloc::collect(
        CALL,
        ts.windows(2).map(|w| {
            let (a, b) = (w[0], w[1]);
            let n = (steps as f64 * (b - a).abs() / duration.abs() - 1e-9)
                .ceil()
                .max(1.0) as usize;
            Run {
                t0: a,
                h: (b - a) / n as f64,
                count: n,
            }
        }),
    )
}

/// Advance `points` through the first `upto` steps of `runs` (RK4).
pub fn flow(field: &Field, points: &mut [DVec3], runs: &[Run], upto: usize) {
    let mut left = upto;
    for r in runs {
        let k = r.count.min(left);
        advect_steps(field, points, r.t0, r.h, 0..k, Method::Rk4);
        left -= k;
        if left == 0 {
            break;
        }
    }
}

/// How the refinement is bounded.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Refinement {
    /// `τ ≥ 1`: an edge is split when its length exceeds `τ · max(rest length, ℓ̄)`.
    pub ratio: f64,
    /// The refined mesh never has more vertices than this.
    pub max_vertices: usize,
    /// At most this many refinement passes after each step.
    pub max_passes: usize,
}

/// A deformed (and refined) mesh.
#[derive(Debug, Clone, Default)]
pub struct Deformed {
    /// Rest positions: the input's, then points of the split rest edges (the rest midpoint, or
    /// the point halfway along a torn edge's path: see the module docs).
    pub rest: Vec<DVec3>,
    /// Deformed positions, one per rest position.
    pub vertices: Vec<DVec3>,
    /// Faces, wound as the input.
    pub faces: Vec<[usize; 3]>,
    /// Refinement passes that split at least one edge.
    pub passes: usize,
    /// Vertex count after each step (length = the number of steps taken; the last one after
    /// the bending splits and the collapses).
    pub step_vertices: Vec<usize>,
    /// New vertices of edges along a slip surface (placed on their generalized path).
    pub torn: usize,
    /// New vertices of edges of material points on one side whose `Φ(rest midpoint)` was torn
    /// away from the chord: placed at the chord midpoint instead.
    pub fallback: usize,
    /// New vertices of torn edges placed at a corner of their path instead of halfway along
    /// it, where the halfway point would have repeated an earlier split (see the module
    /// docs).
    pub cornered: usize,
    /// Vertices on a slip surface at the end (`Ψ(rest, s)` instead of `Φ(rest)`).
    pub slip_vertices: usize,
    /// Edges still over the threshold at the end (0 when the refinement converged).
    pub over_threshold: usize,
    /// Edges still bent beyond the bending bound at the end (see `refine/bend.rs`).
    pub bent: usize,
    /// Vertices added by the bending splits after the integration (see `refine/bend.rs`).
    pub bend_splits: usize,
    /// Whether edges remain over the threshold at the end (a bound, `max_vertices` or
    /// `max_passes`, stopped the refinement).
    pub bounded: bool,
    /// Edges flipped along slip surfaces (see the module docs: flips).
    pub flips: usize,
    /// The change of the enclosed volume by the flips (the sum of their tetrahedra's signed
    /// volumes).
    pub flip_volume: f64,
    /// Edges collapsed along slip surfaces after the integration (see `refine/collapse.rs`): each
    /// removes one vertex and two faces.
    pub collapses: usize,
    /// Vertices of slivers along slip surfaces moved towards their neighbours' centroid on the
    /// surface after the collapses (see `refine/collapse.rs`).
    pub moves: usize,
    /// The change of the enclosed volume by the collapses and moves (each placed to keep it;
    /// the sum of what remains).
    pub collapse_volume: f64,
    /// Wall time of the integration of the mesh's vertices, seconds.
    pub time_integrate: f64,
    /// Wall time of the refinement (edge tests, placement of new vertices, splits), seconds.
    pub time_refine: f64,
}

/// Triangles with the twin of every half-edge: half-edge `3f + k` runs from `faces[f][k]` to
/// `faces[f][(k + 1) % 3]`; `twin[h]` is the opposite half-edge or [`NONE`] on a boundary.
struct Topology {
    faces: Vec<[usize; 3]>,
    twin: Vec<usize>,
}

impl Topology {
    /// Check the faces (indices in range, three distinct vertices) and pair the half-edges:
    /// every undirected edge must belong to one or two faces, traversed in opposite
    /// directions (a consistently wound, edge-manifold mesh).
    fn new(faces: &[[usize; 3]], vertices: usize) -> Result<Topology> {
        for (i, f) in faces.iter().enumerate() {
            if let Some(v) = f.iter().find(|&&v| v >= vertices) {
                return Err(InputError::new(
                    "mesh",
                    format!("face {i} refers to vertex {v}, but there are {vertices} vertices"),
                ));
            }
            if f[0] == f[1] || f[1] == f[2] || f[2] == f[0] {
                return Err(InputError::new(
                    "mesh",
                    format!("face {i} repeats a vertex ({:?})", f),
                ));
            }
        }
        let mut keys: Vec<(usize, usize, usize)> = alloc::collect(
            CALL,
            (0..3 * faces.len()).map(|h| {
                let (a, b) = (faces[h / 3][h % 3], faces[h / 3][(h + 1) % 3]);
                (a.min(b), a.max(b), h)
            }),
        )?;
        keys.par_sort_unstable();
        let mut twin = alloc::filled(CALL, keys.len(), NONE)?;
        let mut i = 0;
        while i < keys.len() {
            let mut j = i + 1;
            while j < keys.len() && keys[j].0 == keys[i].0 && keys[j].1 == keys[i].1 {
                j += 1;
            }
            let (a, b) = (keys[i].0, keys[i].1);
            match j - i {
                1 => {}
                2 => {
                    let (h, g) = (keys[i].2, keys[i + 1].2);
                    if faces[h / 3][h % 3] == faces[g / 3][g % 3] {
                        return Err(InputError::new(
                            "mesh",
                            format!(
                                "faces {} and {} run through edge ({a}, {b}) in the same \
                                 direction: the faces are not consistently wound",
                                h / 3,
                                g / 3
                            ),
                        ));
                    }
                    twin[h] = g;
                    twin[g] = h;
                }
                k => {
                    return Err(InputError::new(
                        "mesh",
                        format!("edge ({a}, {b}) belongs to {k} faces (at most 2)"),
                    ));
                }
            }
            i = j;
        }
        Ok(Topology {
            faces: alloc::copied(CALL, faces)?,
            twin,
        })
    }

    fn ends(&self, h: usize) -> (usize, usize) {
        let f = &self.faces[h / 3];
        (f[h % 3], f[(h + 1) % 3])
    }
}

/// The smallest angle of the triangle `(p, q, r)`, radians (0 for a degenerate one).
fn min_angle(p: DVec3, q: DVec3, r: DVec3) -> f64 {
    let at = |o: DVec3, x: DVec3, y: DVec3| {
        let (u, v) = (x - o, y - o);
        u.cross(v).length().atan2(u.dot(v))
    };
    at(p, q, r).min(at(q, r, p)).min(at(r, p, q))
}

/// Squared length of half-edge `h` at positions `w`.
fn len2(t: &Topology, w: &[DVec3], h: usize) -> f64 {
    let (a, b) = t.ends(h);
    w[a].distance_squared(w[b])
}

/// The refinement state during one deformation.
struct Refiner<'a> {
    field: &'a Field,
    runs: &'a [Run],
    opts: Refinement,
    /// `ℓ̄²`: the squared mean rest edge length.
    mean2: f64,
    topo: Topology,
    rest: Vec<DVec3>,
    /// How each vertex is carried ([`slip::Carry`]): on a slip surface with its blend `s`
    /// (`Ψ(rest, s)`), or as material of one side of it (`Φ(rest)`).
    carry: Vec<Carry>,
    /// The time at which the rest mesh is given (the start of the steps).
    start: f64,
    bounded: bool,
    torn: usize,
    fallback: usize,
    cornered: usize,
    passes: usize,
    /// Faces split since the last flips.
    touched: Vec<usize>,
    flips: usize,
    flip_volume: f64,
    collapses: usize,
    collapse_volume: f64,
    moves: usize,
    /// The input's vertex count (its vertices are never collapsed away).
    inputs: usize,
    /// The vertices placed at a chord midpoint instead of `Φ(rest)`, in increasing order.
    chords: Vec<usize>,
    /// Edges still bent (see `refine/bend.rs`) after the bending splits.
    bent: usize,
    /// Vertices added by the bending splits.
    bend_splits: usize,
    /// Whether a bound (`max_vertices`, or `max_passes` rounds) stopped the bending splits
    /// with bent edges left that they would have split.
    bend_bounded: bool,
    /// The volume an edge's deviation may account for before it is split
    /// ([`bend::VOLUME`] × |rest volume| / the input's edge count).
    share: f64,
}

/// A point of the generalized rest mesh (see the module docs): a material rest point, or a
/// rest point on a slip surface with its blend `s` (0 outside, 1 inside).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Gen {
    Material(DVec3),
    Slip(DVec3, f64),
}

impl Gen {
    fn rest(self) -> DVec3 {
        match self {
            Gen::Material(x) | Gen::Slip(x, _) => x,
        }
    }

    /// The point a fraction `f` along the piece from `self` to `other`: a material point on
    /// a piece with a material end, a slip point (rest point and blend interpolated) on a
    /// piece along the slip surface.
    fn lerp(self, other: Gen, f: f64) -> Gen {
        match (self, other) {
            (Gen::Slip(x, s), Gen::Slip(y, r)) => Gen::Slip(x.lerp(y, f), s + f * (r - s)),
            _ => Gen::Material(self.rest().lerp(other.rest(), f)),
        }
    }
}

/// Advect the closed mesh `(rest, faces)` along `field` through the steps of `runs`,
/// refining after every step when `refinement` is given (see the module docs). With
/// `check`, a mesh that does not bound a solid (open, or wound inwards; see
/// [`crate::mesh::closed`]) is refused naming `mesh`: its volume means nothing. Edges in
/// more than two faces or traversed twice in one direction are refused either way. `tick(done,
/// total)` is called after every step; when it returns `false` the deformation stops and
/// `Ok(None)` is returned.
pub fn deform(
    field: &Field,
    rest: &[DVec3],
    faces: &[[usize; 3]],
    runs: &[Run],
    refinement: Option<Refinement>,
    check: bool,
    tick: &mut dyn FnMut(usize, usize) -> bool,
) -> Result<Option<Deformed>> {
    if let Some(r) = refinement
        && !(r.ratio >= 1.0 && r.ratio.is_finite())
    {
        return Err(InputError::new(
            "refine",
            format!(
                "must be at least 1 (an edge is split when it grows beyond refine × its rest \
                 length) and finite, got {:?}",
                r.ratio
            ),
        ));
    }
    let topo = Topology::new(faces, rest.len())?;
    if check {
        // one linear pass over the faces before the first step (not polled: it takes about
        // what one step takes)
        crate::mesh::closed::closed_volume_centroid(rest, faces, &cancel::never).map_err(
            |mut e| {
                if e.kind == crate::error::ErrorKind::Invalid {
                    e.msg.push_str("; pass check=False to deform it anyway");
                }
                e
            },
        )?;
    }
    let edges = topo.twin.iter().enumerate();
    let (sum, count) =
        edges
            .filter(|&(h, &t)| t == NONE || h < t)
            .fold((0.0, 0usize), |(s, c), (h, _)| {
                let (a, b) = topo.ends(h);
                (s + rest[a].distance(rest[b]), c + 1)
            });
    let mean = if count > 0 { sum / count as f64 } else { 0.0 };
    let mut r = Refiner {
        field,
        runs,
        opts: refinement.unwrap_or(Refinement {
            ratio: 1.0,
            max_vertices: rest.len(),
            max_passes: 0,
        }),
        mean2: mean * mean,
        topo,
        rest: alloc::copied(CALL, rest)?,
        carry: Vec::new(),
        start: runs.first().map_or(0.0, |r| r.t0),
        bounded: false,
        torn: 0,
        fallback: 0,
        cornered: 0,
        passes: 0,
        touched: Vec::new(),
        flips: 0,
        flip_volume: 0.0,
        collapses: 0,
        collapse_volume: 0.0,
        moves: 0,
        inputs: rest.len(),
        chords: Vec::new(),
        bent: 0,
        bend_splits: 0,
        bend_bounded: false,
        share: if count > 0 {
            bend::VOLUME * crate::math::mesh::signed_volume(rest, faces).abs() / count as f64
        } else {
            0.0
        },
    };
    r.carry = alloc::collect(CALL, rest.iter().map(|&x| r.carry_of(Gen::Material(x))))?;
    let mut w = alloc::copied(CALL, rest)?;
    let total: usize = runs.iter().map(|r| r.count).sum();
    let mut out = Deformed::default();
    let mut done = 0;
    for run in runs {
        for j in 0..run.count {
            let clock = Instant::now();
            slip::step(field, &mut w, &r.carry, run, j);
            out.time_integrate += clock.elapsed().as_secs_f64();
            done += 1;
            if refinement.is_some() {
                let clock = Instant::now();
                r.refine(&mut w, done, run.t0 + run.h * (j + 1) as f64)?;
                r.flip_touched(&w)?;
                out.time_refine += clock.elapsed().as_secs_f64();
            }
            out.step_vertices.push(w.len());
            if !tick(done, total) {
                return Ok(None);
            }
        }
    }
    if refinement.is_some() {
        let clock = Instant::now();
        r.split_bends(&mut w, done)?;
        if let Some(last) = out.step_vertices.last_mut() {
            *last = w.len();
        }
        // the strip goes on shearing after a step's flips: a last round over all of it
        let mut touched = alloc::with_capacity(CALL, r.topo.faces.len())?;
        touched.extend((0..r.topo.faces.len()).filter(|&f| {
            r.topo.faces[f]
                .iter()
                .any(|&v| matches!(r.carry[v], Carry::Surface(_)))
        }));
        r.touched = touched;
        r.flip_touched(&w)?;
        // the slivers and folds flips cannot mend: collapses and moves, each keeping the
        // volume, on a converged mesh (a refinement a bound stopped keeps every vertex it got)
        if r.over_edges(&w)?.is_empty() {
            let end = runs.last().map_or(r.start, |l| l.t0 + l.h * l.count as f64);
            r.collapse_slivers(&mut w, end)?;
            if let Some(last) = out.step_vertices.last_mut() {
                *last = w.len();
            }
        }
        out.time_refine += clock.elapsed().as_secs_f64();
    }
    if refinement.is_some() {
        out.over_threshold = r.over_edges(&w)?.len();
    }
    // not converged whenever edges remain over the threshold, or bent where the bending
    // splits would split them: a bound stopped the refinement (every edge, torn ones too, is
    // shortened by its split; see the module docs)
    out.bounded = out.over_threshold > 0 || r.bend_bounded;
    out.bent = r.bent;
    out.bend_splits = r.bend_splits;
    out.passes = r.passes;
    out.torn = r.torn;
    out.fallback = r.fallback;
    out.cornered = r.cornered;
    out.flips = r.flips;
    out.flip_volume = r.flip_volume;
    out.collapses = r.collapses;
    out.collapse_volume = r.collapse_volume;
    out.moves = r.moves;
    out.slip_vertices = r
        .carry
        .iter()
        .filter(|c| matches!(c, Carry::Surface(_)))
        .count();
    out.rest = r.rest;
    out.vertices = w;
    out.faces = r.topo.faces;
    Ok(Some(out))
}
