//! Splits where the flow bends an edge, not only where it stretches it.
//!
//! A flat face between vertices that follow the flow `Φ` exactly misses the deformed surface
//! `Φ(rest face)` by about the deviation of `Φ` from its chords: for an edge `(a, b)` with
//! rest midpoint `m`,
//!
//! `δ = |Φ(m) − (Φ(a) + Φ(b))/2| ≈ ℓ² |∂²Φ/∂s²| / 8`,
//!
//! `ℓ` the edge's rest length and `s` arc length along it. The quadratic patch through a
//! face's corners and edge midpoints `Φ(m)` encloses, beyond the flat faces, the volume
//! `Σ_e δ_e · n_e / 6` (`δ_e` the vector deviation, `n_e` the sum of the unnormalised normals
//! `(y − x) × (z − x)` of the edge's two faces), so `|δ · n| / 6` is the volume an edge
//! accounts for. Lengths alone do not see it: a
//! tool pressing into the middle of a long flat face, a shear or a twist bends faces
//! without stretching their edges much, and the flat faces then lose volume (a long
//! triangle fan pressed by a cube lost 0.9 % of a sphere's volume with no edge over the
//! threshold) or fold over their neighbours. Zheng's thesis (§13.2) places a new vertex at
//! `Φ(m)` so that the refined mesh follows the curved image; the same deviation, relative to
//! the edge, measures where the mesh needs it:
//!
//! * after the integration, every edge of one side's material (no slip surface between its
//!   ends, both ends at `Φ(rest)`) longer than [`SHORTEST`] × `ℓ̄` whose `δ` exceeds
//!   [`BEND`] × `|Φ(a) − Φ(b)|`, or, where both ends are carried by the field (no slip
//!   surface near them: [`Carry::Free`]), whose `δ` accounts for more than [`VOLUME`] × the
//!   rest volume `V` per input edge (`E` edges), is refined like an edge over the length
//!   threshold (`|δ · n| / 6 > VOLUME · |V| / E`; a twist shears faces by less than
//!   [`BEND`] per edge yet loses volume over the whole mesh): the
//!   terminal edge of its longest-edge propagation path (Rivara 1997) is split at `Φ` of its
//!   rest midpoint. A new vertex is `Φ(rest)` whether it is made during the integration or
//!   after it, so splitting afterwards gives the vertices that splitting during it would;
//! * the edges of the faces a round split, and the bent edges it left, are tested in the
//!   next, until a round splits nothing, for at most `max_passes` rounds (and within
//!   `max_vertices`; bent edges left by either bound make the result not converged). Near a
//!   slip surface, a bent edge whose path ends at an edge whose `Φ(rest midpoint)` is torn
//!   away from the chord (a flow the steps do not resolve) is left unsplit: the chord
//!   midpoint would resolve nothing. Where the field is smooth (both ends and the rest
//!   midpoint [`Carry::Free`]) the steps resolve `Φ(m)` however far it lies from the chord
//!   (a twist turns the midpoint of a long edge of a coarse capsule by 0.4 of the edge off
//!   it), so such an edge is split there: leaving them lost 11 % of the capsule's volume. Halving an edge divides its `δ/ℓ` by about two, so
//!   a smooth flow is resolved in a few rounds; the edges still bent at the end are counted
//!   ([`super::Deformed::bent`]).

use glam::DVec3;

use super::split::TORN;
use super::{CALL, Gen, Refiner};
use crate::deform::slip::Carry;
use crate::error::Result;
use crate::run::alloc;

/// An edge is bent when `Φ` of its rest midpoint lies farther than this fraction of the edge
/// from the chord midpoint: the flat face then misses the surface by about `BEND · ℓ`.
pub(super) const BEND: f64 = 0.06;

/// An edge whose deviation accounts for more than this fraction of the rest volume per
/// input edge is bent (where the flow is smooth: both ends carried by the field).
pub(super) const VOLUME: f64 = 2e-3;

/// Edges shorter than this fraction of the mean rest edge `ℓ̄` are not split for bending.
const SHORTEST: f64 = 0.25;

impl Refiner<'_> {
    /// Whether vertex `v` sits at `Φ` of its rest point (material, not a chord midpoint).
    fn at_flow(&self, v: usize) -> bool {
        !matches!(self.carry[v], Carry::Surface(_)) && self.chords.binary_search(&v).is_err()
    }

    /// Whether the edge `(a, b)` with rest midpoint `m` lies where the field is smooth: both
    /// ends and the midpoint carried by the field, no slip surface near them. `Φ(m)` is then
    /// resolved by the steps however far it lies from the chord (a twist turns a long edge's
    /// midpoint far from it), so a bent edge is split there.
    pub(super) fn smooth(&self, a: usize, b: usize, m: DVec3) -> bool {
        matches!(self.carry[a], Carry::Free)
            && matches!(self.carry[b], Carry::Free)
            && matches!(self.carry_of(Gen::Material(m)), Carry::Free)
    }

    /// `|δ · n| / 6`: the volume between the two faces of half-edge `e` and the quadratic
    /// patch that the deviation `d` of its midpoint accounts for (`n` the sum of the faces'
    /// unnormalised normals at `w`).
    fn share_of(&self, w: &[DVec3], e: usize, d: DVec3) -> f64 {
        let normal = |h: usize| {
            let [x, y, z] = self.topo.faces[h / 3];
            (w[y] - w[x]).cross(w[z] - w[x])
        };
        let t = self.topo.twin[e];
        let n = normal(e)
            + if t == super::NONE {
                DVec3::ZERO
            } else {
                normal(t)
            };
        d.dot(n).abs() / 6.0
    }

    /// The half-edges (one per undirected edge) among the edges of `faces` that are bent
    /// at positions `w` after `done` steps.
    fn bent_edges(&self, w: &[DVec3], faces: &[usize], done: usize) -> Result<Vec<usize>> {
        let shortest2 = SHORTEST * SHORTEST * self.mean2;
        let mut cand = alloc::with_capacity(CALL, 3 * faces.len())?;
        cand.extend(
            faces
                .iter()
                .flat_map(|&f| 3 * f..3 * f + 3)
                .filter_map(|h| {
                    let e = self.edge(h);
                    let (a, b) = self.topo.ends(e);
                    (self.at_flow(a)
                        && self.at_flow(b)
                        && w[a].distance_squared(w[b]) > shortest2
                        && self.path(a, b).is_none())
                    .then_some(e)
                }),
        );
        cand.sort_unstable();
        cand.dedup();
        let mids: Vec<Gen> = alloc::collect(
            CALL,
            cand.iter().map(|&e| {
                let (a, b) = self.topo.ends(e);
                Gen::Material(0.5 * (self.rest[a] + self.rest[b]))
            }),
        )?;
        // a rest midpoint across a curved slip surface from its edge's ends (both on one
        // side) is not tested: the edge is not the image of one side's material
        let keep: Vec<bool> = alloc::collect(
            CALL,
            mids.iter()
                .zip(&cand)
                .map(|(&m, &e)| self.carry_of(m) == self.carry[self.topo.ends(e).0]),
        )?;
        let at = self.image(&mids, done);
        let mut bent = alloc::with_capacity(CALL, cand.len())?;
        bent.extend(cand.iter().zip(at).zip(keep).filter_map(|((&e, p), keep)| {
            if !keep {
                return None;
            }
            let (a, b) = self.topo.ends(e);
            // both ends carried by the field (the midpoint then too: `keep`)
            let free = matches!(self.carry[a], Carry::Free) && matches!(self.carry[b], Carry::Free);
            let l2 = w[a].distance_squared(w[b]);
            // bent, but not torn away from the chord (a flow the steps do not resolve, whose
            // split would fall back to the chord midpoint and resolve nothing)
            let d = p - 0.5 * (w[a] + w[b]);
            let d2 = d.length_squared();
            let bent = d2 > BEND * BEND * l2 || (free && self.share_of(w, e, d) > self.share);
            (bent && (d2 <= TORN * TORN * l2 || (d2.is_finite() && free))).then_some(e)
        }));
        Ok(bent)
    }

    /// The bending splits after the integration (`done` steps; see the module docs), in
    /// at most `max_passes` rounds.
    pub(super) fn split_bends(&mut self, w: &mut Vec<DVec3>, done: usize) -> Result<()> {
        let end = self
            .runs
            .last()
            .map_or(self.start, |l| l.t0 + l.h * l.count as f64);
        let mut faces: Vec<usize> = alloc::collect(CALL, 0..self.topo.faces.len())?;
        for _ in 0..self.opts.max_passes {
            let bent = self.bent_edges(w, &faces, done)?;
            self.bent = bent.len();
            if bent.is_empty() {
                self.bend_bounded = false;
                return Ok(());
            }
            // the faces of the bent edges keep their indices through the splits: those not
            // split this round are tested again with the faces the splits made or changed
            faces.clear();
            alloc::reserve(CALL, &mut faces, 2 * bent.len())?;
            for &h in &bent {
                faces.push(h / 3);
                let t = self.topo.twin[h];
                if t != super::NONE {
                    faces.push(t / 3);
                }
            }
            let from = self.touched.len();
            let was = std::mem::replace(&mut self.bounded, false);
            let split = self.split_terminals(w, &bent, done, end, false)?;
            // `max_vertices` left too little room for this round's splits
            self.bend_bounded = self.bounded;
            self.bounded |= was;
            if split == 0 {
                return Ok(());
            }
            self.bend_splits += split;
            alloc::reserve(CALL, &mut faces, self.touched.len() - from)?;
            faces.extend_from_slice(&self.touched[from..]);
            faces.sort_unstable();
            faces.dedup();
        }
        self.bent = self.bent_edges(w, &faces, done)?.len();
        // the rounds ran out with edges left to split
        self.bend_bounded |= self.bent > 0;
        Ok(())
    }
}
