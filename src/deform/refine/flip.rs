//! Edge flips (Lawson's max-min angle): the edge `(a, b)` of `[a, b, c]`, `[b, a, d]` becomes
//! `(c, d)`, which changes the enclosed volume by the signed tetrahedron `abcd`.

use glam::DVec3;

use super::{CALL, MAX_VALENCE, NONE, Refiner, Topology, min_angle};
use crate::deform::slip::Carry;
use crate::error::Result;
use crate::run::alloc;

/// A flip changes the enclosed volume by the signed volume of the tetrahedron of its four
/// vertices; it is allowed only below this fraction of `ℓ̄³` (see [`Refiner::flippable`]).
pub(super) const FLIP_VOLUME: f64 = 1e-4;

/// Each new triangle of a flip must face within this angle's cosine (30°) of the pair's
/// vector area, which the flip keeps.
const FLIP_NORMAL: f64 = 0.866;

/// Rounds of flips over the edges of the faces touched by a step's splits.
const FLIP_ROUNDS: usize = 8;

impl Topology {
    /// Flip the edge of half-edge `h`, shared by the faces `[a, b, c]` (`h` = `a → b`) and
    /// `[b, a, d]`, to `(c, d)`: the faces become `[c, a, d]` and `[d, b, c]`, each outer
    /// half-edge kept with its direction (the winding is kept). The caller checks that `h`
    /// has a twin, `c ≠ d` and that `c` and `d` are not joined already.
    fn flip(&mut self, h: usize) {
        let (f, k) = (h / 3, h % 3);
        let t = self.twin[h];
        let (g, j) = (t / 3, t % 3);
        let [a, b, c] = [0, 1, 2].map(|i| self.faces[f][(k + i) % 3]);
        let d = self.faces[g][(j + 2) % 3];
        let bc = self.twin[3 * f + (k + 1) % 3];
        let ca = self.twin[3 * f + (k + 2) % 3];
        let ad = self.twin[3 * g + (j + 1) % 3];
        let db = self.twin[3 * g + (j + 2) % 3];
        self.faces[f] = [c, a, d];
        self.faces[g] = [d, b, c];
        for (x, y) in [
            (3 * f, ca),
            (3 * f + 1, ad),
            (3 * f + 2, 3 * g + 2),
            (3 * g, db),
            (3 * g + 1, bc),
        ] {
            self.twin[x] = y;
            if y != NONE {
                self.twin[y] = x;
            }
        }
    }

    /// Whether the vertex `u` at which half-edge `e` starts is joined to `v` by an edge: a
    /// walk around `u`. `None` at a boundary or beyond [`MAX_VALENCE`] edges.
    fn joined(&self, e: usize, v: usize) -> Option<bool> {
        let mut x = e;
        for _ in 0..MAX_VALENCE {
            if self.ends(x).1 == v {
                return Some(true);
            }
            // the half-edge into u in the same face, then its twin out of u
            let t = self.twin[3 * (x / 3) + (x % 3 + 2) % 3];
            if t == NONE {
                return None;
            }
            x = t;
            if x == e {
                return Some(false);
            }
        }
        None
    }
}

impl Refiner<'_> {
    /// Whether the edge of half-edge `h` (faces `[a, b, c]` and `[b, a, d]`) is flipped to
    /// `(c, d)` at positions `w`: an edge with a vertex on a slip surface whose flip raises
    /// the smaller of the two triangles' smallest angles, keeps the mesh edge-manifold (`c`
    /// and `d` distinct and not joined), does not fold (each new triangle faces within 30° of
    /// the pair's vector area, which a flip keeps), leaves no edge over the threshold,
    /// keeps the rest mesh's volume (its tetrahedron of the four rest points is flat) and
    /// changes the enclosed volume — by the signed volume of the tetrahedron `abcd` — by at
    /// most [`FLIP_VOLUME`] × `ℓ̄³`.
    fn flippable(&self, w: &[DVec3], h: usize) -> bool {
        let t = self.topo.twin[h];
        if t == NONE {
            return false;
        }
        let (f, k) = (h / 3, h % 3);
        let [a, b, c] = [0, 1, 2].map(|i| self.topo.faces[f][(k + i) % 3]);
        let d = self.topo.faces[t / 3][(t % 3 + 2) % 3];
        if c == d
            || ![a, b, c, d]
                .iter()
                .any(|&v| matches!(self.carry[v], Carry::Surface(_)))
        {
            return false;
        }
        let [pa, pb, pc, pd] = [a, b, c, d].map(|v| w[v]);
        let old = min_angle(pa, pb, pc).min(min_angle(pb, pa, pd));
        let new = min_angle(pc, pa, pd).min(min_angle(pd, pb, pc));
        if !(new > old * (1.0 + 1e-9)) {
            return false;
        }
        // the rest mesh keeps its volume: its tetrahedron abcd is flat (two rest points the
        // same, as along a strip of surface points of one rest point, or exactly coplanar)
        let x = [a, b, c, d].map(|v| self.rest[v]);
        let same = (0..4).any(|i| (i + 1..4).any(|j| x[i] == x[j]));
        if !same && (x[1] - x[0]).cross(x[2] - x[0]).dot(x[3] - x[0]) != 0.0 {
            return false;
        }
        let tet = (pb - pa).cross(pc - pa).dot(pd - pa) / 6.0;
        if !(tet.abs() <= FLIP_VOLUME * self.mean2 * self.mean2.sqrt()) {
            return false;
        }
        let area = (pb - pa).cross(pc - pa) + (pa - pb).cross(pd - pb);
        let faces_along = |n: DVec3| n.dot(area) >= FLIP_NORMAL * n.length() * area.length();
        if area.length_squared() == 0.0
            || !faces_along((pa - pc).cross(pd - pc))
            || !faces_along((pb - pd).cross(pc - pd))
        {
            return false;
        }
        let rest2 = self.rest[c].distance_squared(self.rest[d]).max(self.mean2);
        if pc.distance_squared(pd) > self.opts.ratio * self.opts.ratio * rest2 {
            return false;
        }
        self.topo.joined(3 * f + (k + 2) % 3, d) == Some(false)
    }

    /// Flips (see [`Refiner::flippable`]) over the edges of the faces split since the last
    /// call, then over the edges of the flipped faces, for at most [`FLIP_ROUNDS`] rounds.
    pub(super) fn flip_touched(&mut self, w: &[DVec3]) -> Result<()> {
        let mut queue = alloc::with_capacity(CALL, self.touched.len().saturating_mul(3))?;
        queue.extend(self.touched.drain(..).flat_map(|f| 3 * f..3 * f + 3));
        for _ in 0..FLIP_ROUNDS {
            if queue.is_empty() {
                break;
            }
            queue.sort_unstable();
            queue.dedup();
            let mut next: Vec<usize> = Vec::new();
            for &h in &queue {
                if self.flippable(w, h) {
                    alloc::reserve(CALL, &mut next, 6)?;
                    let (f, g) = (h / 3, self.topo.twin[h] / 3);
                    let [a, b, c] = [0, 1, 2].map(|i| w[self.topo.faces[f][(h % 3 + i) % 3]]);
                    let d = w[self.topo.faces[g][(self.topo.twin[h] % 3 + 2) % 3]];
                    // the faces' signed volume gains the tetrahedron abcd
                    self.flip_volume += (b - a).cross(c - a).dot(d - a) / 6.0;
                    self.topo.flip(h);
                    self.flips += 1;
                    next.extend((3 * f..3 * f + 3).chain(3 * g..3 * g + 3));
                }
            }
            queue = next;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{sphere, watertight};
    use super::*;
    use crate::math::mesh::signed_volume as volume;

    #[test]
    fn a_flip_keeps_the_mesh_closed_and_wound_and_changes_the_volume_by_its_tetrahedron() {
        let (mut v, f) = sphere(1);
        let mut t = Topology::new(&f, v.len()).unwrap();
        // an edge between two of the six-valent vertices (indices ≥ 6: not the octahedron's)
        let h = (0..3 * f.len())
            .find(|&h| t.ends(h).0 >= 6 && t.ends(h).1 >= 6)
            .unwrap();
        v[t.ends(h).0] *= 1.1; // a non-planar pair: the flip changes the volume
        let g = t.twin[h];
        let [a, b, c] = [0, 1, 2].map(|i| t.faces[h / 3][(h % 3 + i) % 3]);
        let d = t.faces[g / 3][(g % 3 + 2) % 3];
        // the walk around c finds its neighbours a and b, not d (an octahedral sphere's
        // pair of triangles is not a tetrahedron)
        let around_c = 3 * (h / 3) + (h % 3 + 2) % 3;
        assert_eq!(t.joined(around_c, a), Some(true));
        assert_eq!(t.joined(around_c, b), Some(true));
        assert_eq!(t.joined(around_c, d), Some(false));
        let before = volume(&v, &t.faces);
        t.flip(h);
        assert!(watertight(&t.faces, v.len()));
        for (h, &g) in t.twin.iter().enumerate() {
            assert_eq!(t.twin[g], h);
            let ((p, q), (r, s)) = (t.ends(h), t.ends(g));
            assert_eq!((p, q), (s, r));
        }
        let edge = |x: usize, y: usize| {
            t.faces
                .iter()
                .filter(|q| (0..3).any(|k| q[k] == x && q[(k + 1) % 3] == y))
                .count()
        };
        assert_eq!(
            (edge(a, b), edge(b, a), edge(c, d), edge(d, c)),
            (0, 0, 1, 1)
        );
        // the flipped face [c, a, d] starts at c
        assert_eq!(t.joined(3 * (h / 3), d), Some(true));
        // every face still winds outwards, and the volume changes by the tetrahedron abcd
        for q in &t.faces {
            let n = (v[q[1]] - v[q[0]]).cross(v[q[2]] - v[q[0]]);
            assert!(n.dot(v[q[0]] + v[q[1]] + v[q[2]]) > 0.0, "{q:?}");
        }
        let tet = (v[b] - v[a]).cross(v[c] - v[a]).dot(v[d] - v[a]) / 6.0;
        let change = volume(&v, &t.faces) - before;
        assert!(tet.abs() > 1e-4, "{tet}");
        assert!((change - tet).abs() < 1e-14, "{change} vs {tet}");
        // flipping back restores the faces' volume
        let back = (0..3 * t.faces.len())
            .find(|&x| t.ends(x) == (c, d) || t.ends(x) == (d, c))
            .unwrap();
        t.flip(back);
        assert!(watertight(&t.faces, v.len()));
        assert!((volume(&v, &t.faces) - before).abs() < 1e-14);
    }

    #[test]
    fn a_tetrahedron_has_no_edge_to_flip_to() {
        let (v, f) = (
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
        );
        let t = Topology::new(&f, v.len()).unwrap();
        for h in 0..12 {
            let g = t.twin[h];
            let c = t.faces[h / 3][(h % 3 + 2) % 3];
            let d = t.faces[g / 3][(g % 3 + 2) % 3];
            assert_eq!(t.joined(3 * (h / 3) + (h % 3 + 2) % 3, d), Some(true));
            assert_ne!(c, d);
        }
    }
}
