//! Edge collapses that remove the slivers of the strip a slip surface tears open.
//!
//! The strip of a curl tool's surface between the two torn sides ([`super`]: slip surfaces)
//! is filled by vertices `Ψ(p, s)` of a few rest points `p` each, at the blends `s` that the
//! halving of torn edges gave them. Its parametrization by the rest point's place `θ` along
//! the torn curve and the blend `s` is far from isometric: where the torn curve runs along
//! the slip (the sides of a drag, `θ` near ±90° from the drag's direction for the
//! translation tool) the curves `Ψ(p, ·)` of neighbouring rest points lie side by side a
//! fraction `|cos θ|` of their rest distance apart, and the strip narrows to a line. The
//! triangles between neighbouring curves, fine in `(θ, s)`, are needles and caps there, and
//! the triangles of three vertices of one curve (one rest point at three blends) are flat in
//! `(θ, s)` already. Their normals are arbitrary, which shows as teeth along the lip. Flips
//! cannot mend a pair whose four vertices lie on one curve; an edge collapse can.
//!
//! **Collapse** (Hoppe, DeRose, Duchamp, McDonald, Stuetzle, "Mesh optimization", SIGGRAPH
//! 1993, §4.2 and §6.2): the edge `(a, b)` shared by the faces `[a, b, c]` and `[b, a, d]`
//! is contracted to one vertex `m`; the two faces vanish, the other faces of `b` become faces
//! of `m`. On a closed 2-manifold the result is a closed 2-manifold when the *link
//! condition* holds: the vertices joined to both `a` and `b` are exactly `c` and `d` (Dey,
//! Edelsbrunner, Guha, Nekhayev, "Topology preserving edge contraction", 1999, §2; a third
//! common neighbour would give an edge of three faces). The winding of every kept face is
//! kept (a vertex index is replaced inside it), and the two pairs of outer half-edges of the
//! vanishing faces become twins.
//!
//! **Which collapses.** After the integration, on a converged refinement (a refinement that a
//! bound stopped keeps every vertex it got), the edges of the faces with a vertex on the
//! strip that are slivers (a smallest angle under [`SLIVER`]) or folded back against a
//! neighbour (a dihedral angle over 120°), shortest first. The survivor `a` is a point of
//! the strip (`Carry::Surface`); the vertex `b` that vanishes is one too, or a new vertex of
//! a side's material at the lip, never a vertex of the input. The collapse must raise the
//! smallest angle of the faces around `a` and `b` (Hoppe et al.'s energy replaced by the
//! max-min angle of Lawson's flips, so that collapses and flips pursue one measure), or
//! leave fewer slivers without halving it, and not fold (no dihedral angle around `m` over
//! 120° unless one as large was there, no more such edges than before); or, failing that,
//! leave fewer folded edges without more slivers nor halving the smallest angle. It must
//! leave no edge over the refinement threshold (the refinement stays converged), keep the
//! rest mesh's volume (the two rest points the same — a pair on one curve `Ψ(p, ·)` — or the
//! rest point of `m` where the rest volume's change, affine along the rest edge, vanishes,
//! within [`REST_FLAT`] × `ℓ̄³`) and keep the enclosed volume (below).
//!
//! **Placement.** The enclosed volume after the collapse is affine in the position `x` of
//! `m`: `V(x) = V₀ + ∑ det(x, q, r)/6` over the kept faces `[m, q, r]` (Lindstrom and Turk,
//! "Fast and memory efficient polygonal simplification", IEEE Visualization 1998, §3.1:
//! the volume-preserving constraint). `m` stays on the slip surface: `x(τ)` is the point of
//! the chord `(1 − τ) W_a + τ W_b` moved onto it ([`slip::project`]; for a pair on one curve
//! `Ψ(p, ·)` of the translation tool, a great circle of the tool's sphere, this is a point of
//! that curve), and `τ ∈ [0, 1]` solves `V(x(τ)) = V` by regula falsi where the volume
//! changes sign along the chord, else is the end that changes it least. A collapse is made
//! only when the remaining change is at most [`COLLAPSE_VOLUME`] × `ℓ̄³` (for the unit sphere
//! of mean edge 0.038 a thirtieth of the volume `≈ ℓ̄⁴/28` between one face and the sphere;
//! the sum over all collapses and moves is [`super::Deformed::collapse_volume`]). Its blend
//! is `(1 − τ) s_a + τ s_b` (`s_a` when `b` is material).
//!
//! **Moves.** A vertex of the strip of a sliver or fold left after a round of collapses is
//! moved towards the centroid of its neighbours (a fraction 1, ½ or ¼ of the way, moved onto
//! the surface: tangential Laplacian smoothing; Field, "Laplacian smoothing and Delaunay
//! triangulations", 1988) where that passes the same tests; the volume's change `(x − W)·G`,
//! `G` a third of the link's vector area, is second order in a tangential move. Rounds of
//! collapses, moves and flips over the strip repeat while they change something, at most
//! [`COLLAPSE_ROUNDS`] times.
//!
//! **Measured** on the 10,242-vertex icosphere dragged half a radius by a curl tool of radius
//! 0.9 centred on its surface (9 steps): the band's faces with a smallest angle under 1° go
//! from 32.3% (flips only) to 1.3%, its folded faces from 6,179 to 907, the vertices from
//! 23,951 to 19,487 (4,464 collapses, 1,875 moves), the volume change from −4.18e-5 to
//! −4.22e-5. The folds left are mostly at the lip between faces with vertices of a side's
//! material, which no collapse with a survivor on the surface can move.

use glam::DVec3;

use super::{CALL, MAX_VALENCE, NONE, Refiner, Topology, min_angle};
use crate::deform::slip::{self, Carry};
use crate::error::Result;
use crate::run::alloc;

/// Faces of the strip with a smallest angle under this (1°, radians) are collapsed away.
pub(super) const SLIVER: f64 = 1.0 * std::f64::consts::PI / 180.0;

/// A collapse may change the enclosed volume by at most this fraction of `ℓ̄³` (as a flip).
pub(super) const COLLAPSE_VOLUME: f64 = 1e-3;

/// The rest faces around a collapse of two different rest points must keep the rest volume
/// within this fraction of `ℓ̄³` (flat up to rounding).
const REST_FLAT: f64 = 1e-12;

/// `cos 120°`: two faces meeting at a dihedral angle over 120° are folded back.
const FOLD_COS: f64 = -0.5;

/// Rounds of collapses, each followed by flips over the strip.
const COLLAPSE_ROUNDS: usize = 4;

/// Regula falsi steps of the volume-preserving placement, which stop once the change is
/// below `PLACE_TOLERANCE` × the allowed one.
const PLACE_STEPS: usize = 12;
const PLACE_TOLERANCE: f64 = 1e-6;

impl Topology {
    /// The half-edges out of the vertex at which `e` starts, in order around it; `None` at a
    /// boundary or beyond [`MAX_VALENCE`] edges.
    pub(super) fn star(&self, e: usize) -> Option<Vec<usize>> {
        let mut out = Vec::new();
        let mut x = e;
        for _ in 0..MAX_VALENCE {
            out.push(x);
            let t = self.twin[3 * (x / 3) + (x % 3 + 2) % 3];
            if t == NONE {
                return None;
            }
            x = t;
            if x == e {
                return Some(out);
            }
        }
        None
    }

    /// Whether the edge of half-edge `h` (faces `[a, b, c]`, `[b, a, d]`) can be collapsed
    /// without leaving the closed 2-manifolds: it has a twin, `c ≠ d`, and the links of `a`
    /// and `b` meet in the link of the edge only (Dey et al. §2): no common neighbour but `c`
    /// and `d`, and not both faces `acd` and `bcd` (a tetrahedron, whose contraction leaves
    /// two faces on three vertices). Returns the stars of `a` and `b` (their outgoing
    /// half-edges) when it can.
    pub(super) fn collapsible(&self, h: usize) -> Option<(Vec<usize>, Vec<usize>)> {
        let t = self.twin[h];
        if t == NONE {
            return None;
        }
        let c = self.faces[h / 3][(h % 3 + 2) % 3];
        let d = self.faces[t / 3][(t % 3 + 2) % 3];
        if c == d {
            return None;
        }
        let (sa, sb) = (self.star(h)?, self.star(t)?);
        // the edge (c, d) in both links (faces acd and bcd, as on a tetrahedron): the
        // contraction would leave two faces on the same three vertices
        let has_cd = |star: &[usize]| {
            star.iter().any(|&e| {
                let q = self.faces[e / 3];
                q.contains(&c) && q.contains(&d)
            })
        };
        if has_cd(&sa) && has_cd(&sb) {
            return None;
        }
        let around_b: Vec<usize> = sb.iter().map(|&e| self.ends(e).1).collect();
        let common = sa
            .iter()
            .filter(|&&e| around_b.contains(&self.ends(e).1))
            .count();
        (common == 2).then_some((sa, sb))
    }

    /// Collapse half-edge `h` = `a → b` (faces `[a, b, c]` and `[b, a, d]`): `b` is replaced by
    /// `a` in its other faces, the two faces are marked in `dead` and their outer half-edges
    /// `(c, b)`/`(a, c)` and `(d, a)`/`(b, d)` become twins. The caller checked
    /// [`Topology::collapsible`]; `star_b` is the star of `b` it returned.
    pub(super) fn collapse(&mut self, h: usize, star_b: &[usize], dead: &mut [bool]) {
        let t = self.twin[h];
        let (f, k, g, j) = (h / 3, h % 3, t / 3, t % 3);
        let (a, b) = self.ends(h);
        let x1 = self.twin[3 * f + (k + 1) % 3]; // twin of b → c
        let x2 = self.twin[3 * f + (k + 2) % 3]; // twin of c → a
        let y1 = self.twin[3 * g + (j + 1) % 3]; // twin of a → d
        let y2 = self.twin[3 * g + (j + 2) % 3]; // twin of d → b
        for &e in star_b {
            let q = e / 3;
            if q != f && q != g {
                for v in self.faces[q].iter_mut() {
                    if *v == b {
                        *v = a;
                    }
                }
            }
        }
        self.twin[x1] = x2;
        self.twin[x2] = x1;
        self.twin[y1] = y2;
        self.twin[y2] = y1;
        for i in 0..3 {
            self.twin[3 * f + i] = NONE;
            self.twin[3 * g + i] = NONE;
        }
        dead[f] = true;
        dead[g] = true;
    }

    /// Drop the faces marked in `dead`, renumbering the half-edges of the others.
    pub(super) fn compact(&mut self, dead: &[bool]) -> Result<()> {
        let mut map = alloc::filled(CALL, self.faces.len(), NONE)?;
        let mut n = 0;
        for (f, &d) in dead.iter().enumerate() {
            if !d {
                map[f] = n;
                n += 1;
            }
        }
        let mut faces = alloc::with_capacity(CALL, n)?;
        let mut twin = alloc::with_capacity(CALL, 3 * n)?;
        for f in (0..self.faces.len()).filter(|&f| !dead[f]) {
            faces.push(self.faces[f]);
            for k in 0..3 {
                let x = self.twin[3 * f + k];
                twin.push(if x == NONE {
                    NONE
                } else {
                    3 * map[x / 3] + x % 3
                });
            }
        }
        self.faces = faces;
        self.twin = twin;
        Ok(())
    }
}

/// `det(p, q, r) = p · (q × r)`: six times the signed volume of the tetrahedron `(0, p, q, r)`.
fn det(t: [DVec3; 3]) -> f64 {
    t[0].dot(t[1].cross(t[2]))
}

fn unit_normal(t: [DVec3; 3]) -> DVec3 {
    (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero()
}

/// A collapse that passed every test: the survivor's position, rest point, blend and the
/// change of the enclosed volume.
struct Plan {
    at: DVec3,
    rest: DVec3,
    s: f64,
    volume: f64,
}

impl Refiner<'_> {
    /// The collapse of half-edge `h` = `a → b` into `a` at time `time` (see the module docs),
    /// if it passes every test, with the stars of `a` and `b`.
    // Kept whole: the tests run cheapest first on the stars, rest points and volume terms
    // computed once for the edge; each early `None` is one refused test.
    fn plan_collapse(
        &self,
        w: &[DVec3],
        h: usize,
        time: f64,
    ) -> Option<(Plan, Vec<usize>, Vec<usize>)> {
        let topo = &self.topo;
        let (a, b) = topo.ends(h);
        // the survivor is a point of the strip; the other end is one too, or a new vertex of
        // a side's material (never a vertex of the input)
        let Carry::Surface(s_a) = self.carry[a] else {
            return None;
        };
        if b < self.inputs {
            return None;
        }
        let s_b = match self.carry[b] {
            Carry::Surface(s) => s,
            _ => s_a,
        };
        let (sa, sb) = topo.collapsible(h)?;
        let t = topo.twin[h];
        let (f, g) = (h / 3, t / 3);
        let mut region: Vec<usize> = sa.iter().chain(&sb).map(|&e| e / 3).collect();
        region.sort_unstable();
        region.dedup();
        let kept: Vec<usize> = region
            .iter()
            .copied()
            .filter(|&q| q != f && q != g)
            .collect();
        let merged = |q: usize| topo.faces[q].map(|v| if v == b { a } else { v });
        let scale3 = self.mean2 * self.mean2.sqrt();

        // the rest mesh keeps its volume: its change is affine in the survivor's rest point on
        // the rest edge, `r₀ + σ (r₁ − r₀)` at `(1 − σ) X_a + σ X_b`; σ is its zero on the edge,
        // else the end where it is smaller
        let (xa, xb) = (self.rest[a], self.rest[b]);
        let rest = if xa == xb {
            xa
        } else {
            let old: f64 = region
                .iter()
                .map(|&q| det(topo.faces[q].map(|v| self.rest[v] - xa)))
                .sum();
            let [r0, r1] = [xa, xb].map(|end| {
                let new: f64 = kept
                    .iter()
                    .map(|&q| det(merged(q).map(|v| if v == a { end } else { self.rest[v] } - xa)))
                    .sum();
                (new - old) / 6.0
            });
            let sigma = if r0 * r1 < 0.0 {
                r0 / (r0 - r1)
            } else if r0.abs() <= r1.abs() {
                0.0
            } else {
                1.0
            };
            if !((r0 + sigma * (r1 - r0)).abs() <= REST_FLAT * scale3) {
                return None;
            }
            xa.lerp(xb, sigma)
        };

        // the enclosed volume's change, origin at W_a (the change is origin-free: the link of
        // the region is the same before and after)
        let o = w[a];
        let old: f64 = region
            .iter()
            .map(|&q| det(topo.faces[q].map(|v| w[v] - o)))
            .sum();
        let change = |x: DVec3| {
            let new: f64 = kept
                .iter()
                .map(|&q| det(merged(q).map(|v| if v == a { x - o } else { w[v] - o })))
                .sum();
            (new - old) / 6.0
        };
        // the tests at a placement `x` with rest point `rest`
        let acceptable = |x: DVec3, rest: DVec3| {
            // no edge grows over the threshold (the cheapest test first)
            let ratio2 = self.opts.ratio * self.opts.ratio;
            for &e in sa.iter().chain(&sb) {
                let v = topo.ends(e).1;
                if v != a && v != b {
                    let rest2 = rest.distance_squared(self.rest[v]).max(self.mean2);
                    if x.distance_squared(w[v]) > ratio2 * rest2 {
                        return false;
                    }
                }
            }
            // the smallest angle rises
            let place = |v: usize| if v == a { x } else { w[v] };
            let angle = |p: [DVec3; 3]| min_angle(p[0], p[1], p[2]);
            let (mut before, mut slivers_before) = (f64::INFINITY, 0usize);
            for &q in &region {
                let x = angle(topo.faces[q].map(|v| w[v]));
                before = before.min(x);
                slivers_before += usize::from(x < SLIVER);
            }
            let (mut after, mut slivers_after) = (f64::INFINITY, 0usize);
            for &q in &kept {
                let x = angle(merged(q).map(place));
                after = after.min(x);
                slivers_after += usize::from(x < SLIVER);
            }
            let sharper =
                after > before || (slivers_after < slivers_before && after >= 0.5 * before);
            let kept_angles = after >= 0.5 * before && slivers_after <= slivers_before;

            // no fold: the dihedral angles at the edges of the region's faces, before and after
            // (the outer half-edges of the vanishing faces pair up as in Topology::collapse)
            let rewire = |n: usize| {
                let (k, j) = (h % 3, t % 3);
                let pairs = [
                    (3 * f + (k + 1) % 3, 3 * f + (k + 2) % 3),
                    (3 * g + (j + 1) % 3, 3 * g + (j + 2) % 3),
                ];
                for (p, q) in pairs {
                    if n == p {
                        return topo.twin[q];
                    }
                    if n == q {
                        return topo.twin[p];
                    }
                }
                n
            };
            let normal_old = |q: usize| unit_normal(topo.faces[q].map(|v| w[v]));
            let normal_new = |q: usize| {
                if kept.binary_search(&q).is_ok() {
                    unit_normal(merged(q).map(place))
                } else {
                    normal_old(q)
                }
            };
            let (mut worst_old, mut folds_old) = (1.0f64, 0usize);
            for &q in &region {
                let n = normal_old(q);
                for e in 3 * q..3 * q + 3 {
                    let c = n.dot(normal_old(topo.twin[e] / 3));
                    worst_old = worst_old.min(c);
                    folds_old += usize::from(c < FOLD_COS);
                }
            }
            let (mut worst_new, mut folds_new) = (1.0f64, 0usize);
            for &q in &kept {
                let n = normal_new(q);
                for e in 3 * q..3 * q + 3 {
                    let c = n.dot(normal_new(rewire(topo.twin[e]) / 3));
                    worst_new = worst_new.min(c);
                    folds_new += usize::from(c < FOLD_COS);
                }
            }
            let unfolded = worst_new >= worst_old.min(FOLD_COS) && folds_new <= folds_old;
            if !((sharper && unfolded) || (kept_angles && folds_new < folds_old)) {
                return false;
            }
            true
        };
        // the volume's change is affine along the chord: a cheap first estimate of the
        // placement, tested before the placement on the surface
        let (v0, v1) = (change(w[a]), change(w[b]));
        let guess = if v0 * v1 < 0.0 {
            v0 / (v0 - v1)
        } else if v0.abs() <= v1.abs() {
            0.0
        } else {
            1.0
        };
        if !acceptable(w[a].lerp(w[b], guess), rest) {
            return None;
        }
        let on = |tau: f64| slip::project(self.field, w[a].lerp(w[b], tau), time).map(|y| y.0);
        let (x0, x1) = (on(0.0)?, on(1.0)?);
        let (v0, v1) = (change(x0), change(x1));
        let (mut tau, mut x, mut v) = if v0.abs() <= v1.abs() {
            (0.0, x0, v0)
        } else {
            (1.0, x1, v1)
        };
        if v0 * v1 < 0.0 {
            let (mut lo, mut flo, mut hi, mut fhi) = (0.0, v0, 1.0, v1);
            for _ in 0..PLACE_STEPS {
                let m = (lo - flo * (hi - lo) / (fhi - flo)).clamp(0.0, 1.0);
                let xm = on(m)?;
                let fm = change(xm);
                if fm.abs() < v.abs() {
                    (tau, x, v) = (m, xm, fm);
                }
                if fm.abs() <= PLACE_TOLERANCE * COLLAPSE_VOLUME * scale3 {
                    break;
                }
                if (fm < 0.0) == (flo < 0.0) {
                    (lo, flo) = (m, fm);
                } else {
                    (hi, fhi) = (m, fm);
                }
            }
        }
        if !(v.abs() <= COLLAPSE_VOLUME * scale3) {
            return None;
        }

        if !acceptable(x, rest) {
            return None;
        }
        let plan = Plan {
            at: x,
            rest,
            s: s_a + tau * (s_b - s_a),
            volume: v,
        };
        Some((plan, sa, sb))
    }

    /// A move of the strip vertex at which half-edge `e` starts towards the centroid of its
    /// neighbours, on the slip surface at time `time` (see the module docs: relocation): the
    /// new position and the change of the enclosed volume, if a fraction 1, ½ or ¼ of the way
    /// passes the tests of a collapse.
    fn plan_move(&self, w: &[DVec3], e: usize, time: f64) -> Option<(DVec3, f64)> {
        let topo = &self.topo;
        let v = topo.ends(e).0;
        if !matches!(self.carry[v], Carry::Surface(_)) {
            return None;
        }
        let star = topo.star(e)?;
        let mut faces: Vec<usize> = star.iter().map(|&h| h / 3).collect();
        faces.sort_unstable();
        let o = w[v];
        // the volume's change is (x − o)·G, G the link's vector area over 3 (origin o)
        let g: DVec3 = star
            .iter()
            .map(|&h| {
                let (p, r) = topo.ends(h);
                let q = topo.faces[h / 3][(h % 3 + 2) % 3];
                debug_assert_eq!(p, v);
                (w[r] - o).cross(w[q] - o)
            })
            .sum::<DVec3>()
            / 6.0;
        let centroid = star.iter().map(|&h| w[topo.ends(h).1]).sum::<DVec3>() / star.len() as f64;
        let angle = |t: [DVec3; 3]| min_angle(t[0], t[1], t[2]);
        let before = faces
            .iter()
            .map(|&q| angle(topo.faces[q].map(|u| w[u])))
            .fold(f64::INFINITY, f64::min);
        let normal_old = |q: usize| unit_normal(topo.faces[q].map(|u| w[u]));
        let (mut worst_old, mut folds_old) = (1.0f64, 0usize);
        for &q in &faces {
            let n = normal_old(q);
            for h in 3 * q..3 * q + 3 {
                let c = n.dot(normal_old(topo.twin[h] / 3));
                worst_old = worst_old.min(c);
                folds_old += usize::from(c < FOLD_COS);
            }
        }
        let ratio2 = self.opts.ratio * self.opts.ratio;
        let scale3 = self.mean2 * self.mean2.sqrt();
        for lambda in [1.0, 0.5, 0.25] {
            let (x, _) = slip::project(self.field, o.lerp(centroid, lambda), time)?;
            let change = (x - o).dot(g);
            if !(change.abs() <= COLLAPSE_VOLUME * scale3) {
                continue;
            }
            let place = |u: usize| if u == v { x } else { w[u] };
            let after = faces
                .iter()
                .map(|&q| angle(topo.faces[q].map(place)))
                .fold(f64::INFINITY, f64::min);
            if !(after >= 0.5 * before) {
                continue;
            }
            let long = star.iter().any(|&h| {
                let u = topo.ends(h).1;
                let rest2 = self.rest[v].distance_squared(self.rest[u]).max(self.mean2);
                x.distance_squared(w[u]) > ratio2 * rest2
            });
            if long {
                continue;
            }
            let normal_new = |q: usize| {
                if faces.binary_search(&q).is_ok() {
                    unit_normal(topo.faces[q].map(place))
                } else {
                    normal_old(q)
                }
            };
            let (mut worst_new, mut folds_new) = (1.0f64, 0usize);
            for &q in &faces {
                let n = normal_new(q);
                for h in 3 * q..3 * q + 3 {
                    let c = n.dot(normal_new(topo.twin[h] / 3));
                    worst_new = worst_new.min(c);
                    folds_new += usize::from(c < FOLD_COS);
                }
            }
            let unfolded = worst_new >= worst_old.min(FOLD_COS) && folds_new <= folds_old;
            if !((after > before && unfolded)
                || (folds_new < folds_old && after >= before.min(SLIVER)))
            {
                continue;
            }
            return Some((x, change));
        }
        None
    }

    /// Whether face `q` has a smallest angle under [`SLIVER`] or is folded against a
    /// neighbour (a dihedral angle over 120°).
    fn bad(&self, w: &[DVec3], q: usize) -> bool {
        let t = self.topo.faces[q].map(|v| w[v]);
        if min_angle(t[0], t[1], t[2]) < SLIVER {
            return true;
        }
        let n = unit_normal(t);
        (3 * q..3 * q + 3).any(|e| {
            let o = self.topo.twin[e] / 3;
            n.dot(unit_normal(self.topo.faces[o].map(|v| w[v]))) < FOLD_COS
        })
    }

    /// The faces with a vertex on a slip surface that are [`Refiner::bad`], by their smallest
    /// angle.
    fn bad_faces(&self, w: &[DVec3]) -> Vec<(f64, usize)> {
        let mut out: Vec<(f64, usize)> = (0..self.topo.faces.len())
            .filter(|&q| {
                self.topo.faces[q]
                    .iter()
                    .any(|&v| matches!(self.carry[v], Carry::Surface(_)))
                    && self.bad(w, q)
            })
            .map(|q| {
                let [p, r, s] = self.topo.faces[q].map(|v| w[v]);
                (min_angle(p, r, s), q)
            })
            .collect();
        out.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        out
    }

    /// Collapse the slivers of the strips along slip surfaces at time `time` (see the module
    /// docs), with flips over the strips after each round; the vertices and faces that
    /// vanish are dropped from `w` and the refiner's arrays.
    pub(super) fn collapse_slivers(&mut self, w: &mut Vec<DVec3>, time: f64) -> Result<()> {
        let mut gone = alloc::filled(CALL, w.len(), false)?;
        // vertices moved or merged in a round: the flips after it go over their faces
        let mut changed = alloc::filled(CALL, w.len(), false)?;
        for _ in 0..COLLAPSE_ROUNDS {
            let bad = self.bad_faces(w);
            if bad.is_empty() {
                break;
            }
            let mut dead = alloc::filled(CALL, self.topo.faces.len(), false)?;
            let before = self.collapses;
            for &(_, q) in &bad {
                if dead[q] {
                    continue;
                }
                if !self.bad(w, q) {
                    continue;
                }
                // the face's edges, shortest first, each collapsed either way
                let mut edges: Vec<(f64, usize)> = (3 * q..3 * q + 3)
                    .map(|e| (super::len2(&self.topo, w, e), e))
                    .collect();
                edges.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
                // (the twin of an edge of two strip points is the same collapse, its ends renamed)
                let strip = |v: usize| matches!(self.carry[v], Carry::Surface(_));
                let twins = edges
                    .iter()
                    .filter(|&&(_, e)| {
                        let (a, b) = self.topo.ends(e);
                        !(strip(a) && strip(b))
                    })
                    .map(|&(_, e)| self.topo.twin[e])
                    .collect::<Vec<_>>();
                for e in edges.into_iter().map(|x| x.1).chain(twins) {
                    let Some((plan, _, sb)) = self.plan_collapse(w, e, time) else {
                        continue;
                    };
                    let (a, b) = self.topo.ends(e);
                    w[a] = plan.at;
                    self.rest[a] = plan.rest;
                    self.carry[a] = Carry::Surface(plan.s);
                    self.topo.collapse(e, &sb, &mut dead);
                    gone[b] = true;
                    changed[a] = true;
                    self.collapses += 1;
                    self.collapse_volume += plan.volume;
                    break;
                }
            }
            self.topo.compact(&dead)?;
            // the slivers left: their vertices moved towards their neighbours' centroid
            let moved = self.moves;
            for (_, q) in self.bad_faces(w) {
                if !self.bad(w, q) {
                    continue;
                }
                for e in 3 * q..3 * q + 3 {
                    if let Some((x, change)) = self.plan_move(w, e, time) {
                        let v = self.topo.ends(e).0;
                        w[v] = x;
                        changed[v] = true;
                        self.moves += 1;
                        self.collapse_volume += change;
                        break;
                    }
                }
            }
            if self.collapses == before && self.moves == moved {
                break;
            }
            let mut touched = alloc::with_capacity(CALL, self.topo.faces.len())?;
            touched.extend(
                (0..self.topo.faces.len())
                    .filter(|&q| self.topo.faces[q].iter().any(|&v| changed[v])),
            );
            self.touched = touched;
            changed.fill(false);
            self.flip_touched(w)?;
        }
        // drop the vanished vertices, keeping the order of the others
        if gone.iter().any(|&g| g) {
            let mut map = alloc::filled(CALL, w.len(), NONE)?;
            let mut n = 0;
            for (v, &g) in gone.iter().enumerate() {
                if !g {
                    map[v] = n;
                    w[n] = w[v];
                    self.rest[n] = self.rest[v];
                    self.carry[n] = self.carry[v];
                    n += 1;
                }
            }
            w.truncate(n);
            self.rest.truncate(n);
            self.carry.truncate(n);
            for t in self.topo.faces.iter_mut() {
                *t = t.map(|v| map[v]);
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;
