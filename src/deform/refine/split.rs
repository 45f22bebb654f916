//! Edge splits: the threshold test, longest-edge bisection (Rivara 1984: an edge is split only
//! when it is the longest of both its triangles) and the placement of the new vertices.

use glam::DVec3;
use rayon::prelude::*;

use super::{CALL, Gen, NONE, Refiner, Topology, len2};
use crate::deform::slip::{self, Carry};
use crate::error::Result;
use crate::run::alloc;

/// A placement farther than this fraction of its edge from the chord midpoint marks the edge
/// as torn by the flow (see the module docs).
pub(super) const TORN: f64 = 0.25;

/// A torn edge's halfway point closer than this fraction of the edge to a third vertex of
/// its triangles lands on that vertex (see the module docs: corners).
const COINCIDENT: f64 = 0.05;

/// Bisection steps locating where a rest edge crosses a slip surface.
const CROSSING_STEPS: usize = 60;

impl Topology {
    /// Split half-edge `h` (and its twin) at the new vertex `m`: both triangles bisected.
    fn split(&mut self, h: usize, m: usize) {
        let (f, k) = (h / 3, h % 3);
        let tw = self.twin[h];
        let [a, b, c] = [0, 1, 2].map(|i| self.faces[f][(k + i) % 3]);
        let f2 = self.faces.len();
        let old_f = [3 * f + (k + 1) % 3, 3 * f + (k + 2) % 3]; // b→c, c→a
        let mut outer = vec![
            (3 * f2 + 1, self.twin[old_f[0]]),
            (3 * f + 2, self.twin[old_f[1]]),
        ];
        let mut remap = vec![(old_f[0], 3 * f2 + 1), (old_f[1], 3 * f + 2)];
        self.faces[f] = [a, m, c];
        self.faces.push([m, b, c]);
        self.twin.extend([NONE; 3]);
        let mut inner = vec![(3 * f + 1, 3 * f2 + 2)];
        if tw == NONE {
            self.twin[3 * f] = NONE;
            self.twin[3 * f2] = NONE;
        } else {
            let (g, j) = (tw / 3, tw % 3);
            let d = self.faces[g][(j + 2) % 3];
            let g2 = self.faces.len();
            let old_g = [3 * g + (j + 1) % 3, 3 * g + (j + 2) % 3]; // a→d, d→b
            outer.push((3 * g2 + 1, self.twin[old_g[0]]));
            outer.push((3 * g + 2, self.twin[old_g[1]]));
            remap.push((old_g[0], 3 * g2 + 1));
            remap.push((old_g[1], 3 * g + 2));
            self.faces[g] = [b, m, d];
            self.faces.push([m, a, d]);
            self.twin.extend([NONE; 3]);
            inner.extend([(3 * g + 1, 3 * g2 + 2), (3 * f, 3 * g2), (3 * f2, 3 * g)]);
        }
        for (x, y) in inner {
            self.twin[x] = y;
            self.twin[y] = x;
        }
        // outer neighbours: a twin that pointed into a rewritten slot of f or g follows it
        for (x, y) in outer {
            let y = remap.iter().find(|r| r.0 == y).map_or(y, |r| r.1);
            self.twin[x] = y;
            if y != NONE {
                self.twin[y] = x;
            }
        }
    }
}

impl Refiner<'_> {
    /// The side of the nearest slip surface on which rest point `x` lies: 1 inside (`d < 0`),
    /// 0 outside; `None` where the field has no slip surface.
    fn side(&self, x: DVec3) -> Option<f64> {
        let (d, _) = self.field.slip_surface(x, self.start)?;
        Some(if d < 0.0 { 1.0 } else { 0.0 })
    }

    fn gen_of(&self, v: usize) -> Gen {
        match self.carry[v] {
            Carry::Surface(s) => Gen::Slip(self.rest[v], s),
            _ => Gen::Material(self.rest[v]),
        }
    }

    pub(super) fn carry_of(&self, g: Gen) -> Carry {
        match g {
            Gen::Slip(_, s) => Carry::Surface(s),
            Gen::Material(x) => self.side(x).map_or(Carry::Free, Carry::Side),
        }
    }

    /// Where the rest segment `x → y` (ends on opposite sides) crosses the slip surface.
    fn crossing(&self, x: DVec3, y: DVec3) -> Option<DVec3> {
        let sx = self.side(x)?;
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..CROSSING_STEPS {
            let mid = 0.5 * (lo + hi);
            if self.side(x.lerp(y, mid))? == sx {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Some(x.lerp(y, 0.5 * (lo + hi)))
    }

    /// The generalized path of edge `(a, b)` when it runs along a slip surface (its ends on
    /// the surface or on opposite sides of it): the points where it meets and leaves the
    /// surface between its ends. `None` for an edge of material points on one side.
    pub(super) fn path(&self, a: usize, b: usize) -> Option<Vec<Gen>> {
        let (ga, gb) = (self.gen_of(a), self.gen_of(b));
        match (ga, gb) {
            (Gen::Slip(..), Gen::Slip(..)) => Some(vec![ga, gb]),
            (Gen::Material(x), Gen::Slip(y, _)) => Some(vec![ga, Gen::Slip(y, self.side(x)?), gb]),
            (Gen::Slip(x, _), Gen::Material(y)) => Some(vec![ga, Gen::Slip(x, self.side(y)?), gb]),
            (Gen::Material(x), Gen::Material(y)) => {
                let (sx, sy) = (self.side(x)?, self.side(y)?);
                if sx == sy {
                    return None;
                }
                let p = self.crossing(x, y)?;
                Some(vec![ga, Gen::Slip(p, sx), Gen::Slip(p, sy), gb])
            }
        }
    }

    /// Whether half-edge `h` is over the threshold at positions `w`.
    fn over(&self, w: &[DVec3], h: usize) -> bool {
        let (a, b) = self.topo.ends(h);
        let rest2 = self.rest[a].distance_squared(self.rest[b]).max(self.mean2);
        w[a].distance_squared(w[b]) > self.opts.ratio * self.opts.ratio * rest2
    }

    /// Every undirected edge over the threshold, once (the half-edge with the smaller index).
    /// Marked in parallel, then gathered into a buffer asked for fallibly.
    pub(super) fn over_edges(&self, w: &[DVec3]) -> Result<Vec<usize>> {
        let mut mark = alloc::filled(CALL, self.topo.twin.len(), false)?;
        mark.par_iter_mut().enumerate().for_each(|(h, m)| {
            let t = self.topo.twin[h];
            *m = (t == NONE || h < t) && self.over(w, h);
        });
        let mut over = alloc::with_capacity(CALL, mark.iter().filter(|&&m| m).count())?;
        over.extend(mark.iter().enumerate().filter_map(|(h, &m)| m.then_some(h)));
        Ok(over)
    }

    /// Whether the two triangles of `h` share their third vertex too (the two faces of a
    /// flat "pillow"): bisecting them would join the new vertex to it twice.
    fn folded(&self, h: usize) -> bool {
        let t = self.topo.twin[h];
        t != NONE && self.topo.faces[h / 3][(h + 2) % 3] == self.topo.faces[t / 3][(t + 2) % 3]
    }

    /// The undirected edge of half-edge `h`: the smaller of `h` and its twin.
    pub(super) fn edge(&self, h: usize) -> usize {
        let t = self.topo.twin[h];
        if t == NONE { h } else { h.min(t) }
    }

    /// The longest edge of face `f` at positions `w`, as the half-edge in `f`: the largest
    /// `(squared length, undirected edge)`, a strict order, so that a path of longest edges
    /// cannot cycle.
    fn longest_of(&self, w: &[DVec3], f: usize) -> usize {
        let key = |h: usize| (len2(&self.topo, w, h), self.edge(h));
        let mut best = 3 * f;
        for h in 3 * f + 1..3 * f + 3 {
            let (l, e) = key(h);
            let (bl, be) = key(best);
            if l > bl || (l == bl && e > be) {
                best = h;
            }
        }
        best
    }

    /// The terminal edge of the longest-edge propagation path from half-edge `h` (Rivara
    /// 1997): from a face to the neighbour across its longest edge until that edge is the
    /// longest of both its faces (or lies on the boundary). Bisecting terminal edges only
    /// halves triangles across their longest edge, so no angle falls below half the
    /// smallest angle of the triangles it came from and the refinement ends; splitting a
    /// shorter edge instead can cycle towards a fixed point and stack copies of one vertex.
    fn terminal(&self, w: &[DVec3], h: usize) -> usize {
        let mut e = self.longest_of(w, h / 3);
        // the (length, edge) key grows strictly along the path: at most one visit per face
        for _ in 0..self.topo.faces.len() {
            let t = self.topo.twin[e];
            if t == NONE {
                return e;
            }
            let next = self.longest_of(w, t / 3);
            if next == t {
                return self.edge(e);
            }
            e = next;
        }
        self.edge(e)
    }

    /// Room for the vertices, faces and half-edges `new` splits add (each adds a vertex,
    /// at most two faces and six half-edges, and touches at most four faces), asked for
    /// before the splits so that running out of memory is an error, not an abort.
    fn reserve_splits(&mut self, w: &mut Vec<DVec3>, new: usize) -> Result<()> {
        alloc::reserve(CALL, w, new)?;
        alloc::reserve(CALL, &mut self.rest, new)?;
        alloc::reserve(CALL, &mut self.carry, new)?;
        alloc::reserve(CALL, &mut self.topo.faces, 2 * new)?;
        alloc::reserve(CALL, &mut self.topo.twin, 6 * new)?;
        alloc::reserve(CALL, &mut self.touched, 4 * new)
    }

    /// Refinement passes after step `done` (1-based count of the steps taken), at time `t`.
    pub(super) fn refine(&mut self, w: &mut Vec<DVec3>, done: usize, t: f64) -> Result<()> {
        for _ in 0..self.opts.max_passes {
            let over = self.over_edges(w)?;
            if over.is_empty() || self.split_terminals(w, &over, done, t, true)? == 0 {
                return Ok(());
            }
        }
        if !self.over_edges(w)?.is_empty() {
            self.bounded = true;
        }
        Ok(())
    }

    /// One pass of splits for the edges `triggers` (half-edges): the terminal edges of
    /// their longest-edge paths (from both faces of each), longest first, each once, as many
    /// as share no triangle and `max_vertices` leaves room for (`bounded` is set when it
    /// leaves too little). With `chords` false, an edge of one side's material whose
    /// `Φ(rest midpoint)` is torn away from its chord is left unsplit instead of split at the
    /// chord midpoint. Returns how many were split.
    pub(super) fn split_terminals(
        &mut self,
        w: &mut Vec<DVec3>,
        triggers: &[usize],
        done: usize,
        t: f64,
        chords: bool,
    ) -> Result<usize> {
        let room = self.opts.max_vertices.saturating_sub(w.len());
        if room == 0 {
            self.bounded = true;
            return Ok(0);
        }
        let mut pick: Vec<(f64, usize)> = alloc::with_capacity(CALL, 2 * triggers.len())?;
        for &h in triggers {
            let t = self.topo.twin[h];
            for g in [Some(h), (t != NONE).then_some(t)].into_iter().flatten() {
                let e = self.terminal(w, g);
                pick.push((len2(&self.topo, w, e), e));
            }
        }
        pick.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
        pick.dedup_by_key(|p| p.1);
        let mut used = alloc::filled(CALL, self.topo.faces.len(), false)?;
        let mut chosen = alloc::with_capacity(CALL, room.min(pick.len()))?;
        for &(_, h) in &pick {
            if chosen.len() == room {
                self.bounded = true;
                break;
            }
            let t = self.topo.twin[h];
            if used[h / 3] || (t != NONE && used[t / 3]) || self.folded(h) {
                continue;
            }
            used[h / 3] = true;
            if t != NONE {
                used[t / 3] = true;
            }
            chosen.push(h);
        }
        let mut split = 0;
        if !chosen.is_empty() {
            self.reserve_splits(w, chosen.len())?;
            split = self.place_and_split(w, &chosen, done, t, chords);
            self.passes += usize::from(split > 0);
        }
        Ok(split)
    }

    /// Whether splitting half-edge `h` at position `p` (rest point `x`) would repeat an
    /// earlier split: `p` lands on a third vertex of `h`'s triangles (closer than
    /// [`COINCIDENT`] × `|h|`) while its edge to a third vertex is over the threshold and
    /// longer than `h` (at the chord midpoint the median to the third vertex is shorter than
    /// the longest edge, which is why longest-edge bisection terminates; Rivara 1984).
    fn repeats(&self, w: &[DVec3], h: usize, x: DVec3, p: DVec3) -> bool {
        let l2 = len2(&self.topo, w, h);
        let t = self.topo.twin[h];
        let third = || {
            [Some(h), (t != NONE).then_some(t)]
                .into_iter()
                .flatten()
                .map(|e| self.topo.faces[e / 3][(e + 2) % 3])
        };
        let ratio2 = self.opts.ratio * self.opts.ratio;
        third().any(|o| p.distance_squared(w[o]) < COINCIDENT * COINCIDENT * l2)
            && third().any(|o| {
                let d2 = p.distance_squared(w[o]);
                d2 > l2 && d2 > ratio2 * x.distance_squared(self.rest[o]).max(self.mean2)
            })
    }

    /// A torn edge's new vertex: its chord midpoint `c`, moved onto the nearest slip surface
    /// of the field when one passes within the edge length `l` of it (a Newton step on the
    /// surface's distance, ending a hair on its positive side so that the vertex follows the
    /// material outside the tool).
    fn on_slip(&self, c: DVec3, l: f64, t: f64) -> DVec3 {
        match self.field.slip_surface(c, t) {
            Some((d, g)) if d.abs() < l && g.length_squared() > 0.0 => {
                c - g * ((d - 1e-9 * l) / g.length_squared())
            }
            _ => c,
        }
    }

    /// The deformed positions of generalized rest points after `done` steps: `Φ` of the
    /// material ones, `Ψ` of the slip ones.
    pub(super) fn image(&self, gens: &[Gen], done: usize) -> Vec<DVec3> {
        let mut out: Vec<DVec3> = gens.iter().map(|g| g.rest()).collect();
        let carry: Vec<Carry> = gens.iter().map(|&g| self.carry_of(g)).collect();
        slip::flow(self.field, &mut out, &carry, self.runs, done);
        out
    }

    /// New vertices on the chosen half-edges, then the splits. An edge of material points on
    /// one side gets `Φ(rest midpoint)` (the chord midpoint where that is torn away); an edge
    /// along a slip surface gets the point halfway along its generalized path, measured by
    /// the chords between the images of the path's points.
    /// Returns how many were split (all of `chosen` unless `chords` is false: see
    /// [`Refiner::split_terminals`]).
    // Kept whole: the placement of every new point and the splits that use it share the
    // images of the paths' junctions, computed once for all chosen edges.
    fn place_and_split(
        &mut self,
        w: &mut Vec<DVec3>,
        chosen: &[usize],
        done: usize,
        t: f64,
        chords: bool,
    ) -> usize {
        let mut split = 0;
        let paths: Vec<Option<Vec<Gen>>> = chosen
            .iter()
            .map(|&h| {
                let (a, b) = self.topo.ends(h);
                self.path(a, b)
            })
            .collect();
        // the images of the points where the paths meet and leave a slip surface
        let inner: Vec<Gen> = paths
            .iter()
            .flatten()
            .flat_map(|p| p[1..p.len() - 1].iter().copied())
            .collect();
        let mut junction = self.image(&inner, done).into_iter();
        // per edge: the new point, and on a torn edge's path the corner (a junction that is
        // not one of the edge's ends) nearest to its halfway point, with its image
        let (new, corners): (Vec<Gen>, Vec<Option<(Gen, DVec3)>>) = chosen
            .iter()
            .zip(&paths)
            .map(|(&h, path)| {
                let (a, b) = self.topo.ends(h);
                let Some(path) = path else {
                    return (Gen::Material(0.5 * (self.rest[a] + self.rest[b])), None);
                };
                let mut at = vec![w[a]];
                at.extend(junction.by_ref().take(path.len() - 2));
                at.push(w[b]);
                let lens: Vec<f64> = at.windows(2).map(|q| q[0].distance(q[1])).collect();
                let total: f64 = lens.iter().sum();
                let (mut run, mut corner) = (0.0, None::<(f64, usize)>);
                for j in 1..path.len() - 1 {
                    run += lens[j - 1];
                    let off = (run - 0.5 * total).abs();
                    if path[j] != path[0]
                        && path[j] != path[path.len() - 1]
                        && corner.is_none_or(|(o, _)| off < o)
                    {
                        corner = Some((off, j));
                    }
                }
                let corner = corner.map(|(_, j)| (path[j], at[j]));
                let mut half = 0.5 * total;
                let mut k = 0;
                while k + 1 < lens.len() && half > lens[k] {
                    half -= lens[k];
                    k += 1;
                }
                let f = if lens[k] > 0.0 {
                    (half / lens[k]).clamp(0.0, 1.0)
                } else {
                    0.5
                };
                let g = path[k].lerp(path[k + 1], f);
                // a material point must lie on its piece's side of the surface (else the
                // piece's end on the surface)
                let g = match (g, path[k], path[k + 1]) {
                    (Gen::Material(x), Gen::Material(e), end)
                    | (Gen::Material(x), end, Gen::Material(e))
                        if self.side(x) != self.side(e) =>
                    {
                        end
                    }
                    _ => g,
                };
                (g, corner)
            })
            .unzip();
        let placed = self.image(&new, done);
        for (((&h, (g, p)), path), corner) in chosen
            .iter()
            .zip(new.into_iter().zip(placed))
            .zip(&paths)
            .zip(corners)
        {
            let (a, b) = self.topo.ends(h);
            let (g, p) = match corner {
                Some(c) if self.repeats(w, h, g.rest(), p) => {
                    self.cornered += 1;
                    c
                }
                _ => (g, p),
            };
            let chord = 0.5 * (w[a] + w[b]);
            let l = w[a].distance(w[b]);
            let (p, carry) = match g {
                Gen::Slip(_, s) => (p, Carry::Surface(s)),
                // `!(d <= ...)` also catches a NaN placement
                Gen::Material(x)
                    if path.is_none()
                        && !(p.distance(chord) <= TORN * l)
                        && !(p.is_finite() && !chords && self.smooth(a, b, x)) =>
                {
                    if !chords {
                        continue;
                    }
                    self.fallback += 1;
                    self.torn += 1;
                    self.chords.push(w.len());
                    (self.on_slip(chord, l, t), Carry::Free)
                }
                Gen::Material(x) => (p, self.carry_of(Gen::Material(x))),
            };
            if path.is_some() {
                self.torn += 1;
            }
            let m = w.len();
            w.push(p);
            self.rest.push(g.rest());
            self.carry.push(carry);
            let (n, tw) = (self.topo.faces.len(), self.topo.twin[h]);
            self.topo.split(h, m);
            self.touched.push(h / 3);
            if tw != NONE {
                self.touched.push(tw / 3);
            }
            self.touched.extend(n..self.topo.faces.len());
            split += 1;
        }
        split
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{sphere, watertight};
    use super::*;
    use crate::math::mesh::signed_volume as volume;

    #[test]
    fn splits_keep_the_mesh_closed_and_its_volume() {
        let (v, f) = sphere(2);
        let mut t = Topology::new(&f, v.len()).unwrap();
        let mut w = v.clone();
        for h in [0, 7, 20, 3 * f.len() - 1, 0] {
            let (a, b) = t.ends(h);
            w.push(0.5 * (w[a] + w[b]));
            t.split(h, w.len() - 1);
        }
        assert!(watertight(&t.faces, w.len()));
        assert!((volume(&w, &t.faces) / volume(&v, &f) - 1.0).abs() < 1e-14);
        // every twin points back, and twins run the edge in opposite directions
        for (h, &g) in t.twin.iter().enumerate() {
            assert_eq!(t.twin[g], h);
            let ((a, b), (c, d)) = (t.ends(h), t.ends(g));
            assert_eq!((a, b), (d, c));
        }
    }
}
